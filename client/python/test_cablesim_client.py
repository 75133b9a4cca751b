"""Runs the Python client against a live cablesim-server on a loopback port
and compares the streamed arrays with the CSV of `cablesim run` (the same
engine in another process: the doubles must be identical)."""

import os
import subprocess
import sys
import tempfile
import time
import unittest

import grpc
import numpy as np

import cablesim_client

SOURCE = os.environ["CABLESIM_SOURCE_DIR"]
BIN = os.environ["CABLESIM_BIN_DIR"]


class ClientTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        port_file = os.path.join(cls.tmp.name, "port")
        cls.server = subprocess.Popen(
            [os.path.join(BIN, "cablesim-server"), "--listen=127.0.0.1:0",
             "--data-dir=" + cls.tmp.name, "--port-file=" + port_file, "--workers=1"])
        # Until the server has written its port (or exited): no time limit
        # that a busy machine could exceed.
        while not os.path.exists(port_file):
            if cls.server.poll() is not None:
                raise RuntimeError("cablesim-server exited with %d" % cls.server.returncode)
            time.sleep(0.01)
        with open(port_file) as f:
            cls.address = "127.0.0.1:" + f.read().strip()
        cls.channel = grpc.insecure_channel(cls.address)
        cls.stub = cablesim_client.service_pb2_grpc.CablesimServiceStub(cls.channel)

    @classmethod
    def tearDownClass(cls):
        cls.channel.close()
        cls.server.terminate()
        cls.server.wait(timeout=30)
        cls.tmp.cleanup()

    def scene(self):
        scene = cablesim_client.load_scene(os.path.join(SOURCE, "scenes", "falling-pendulum.json"))
        scene.solver.duration = 0.1
        return scene

    def test_stream_matches_the_cli_and_plots(self):
        scene = self.scene()
        result = cablesim_client.run(self.stub, scene, frames_per_batch=7)
        self.assertEqual(result.summary.status, "ok")
        self.assertEqual(result.data.shape, (101, 17))  # 0.1 s every 1 ms; t, 9 tip, 7
        # Reference: `cablesim run` in-process, written as CSV (17 digits
        # read back exactly).
        scene_path = os.path.join(self.tmp.name, "scene.json")
        csv_path = os.path.join(self.tmp.name, "run.csv")
        from google.protobuf import json_format
        with open(scene_path, "w") as f:
            f.write(json_format.MessageToJson(scene))
        subprocess.run([os.path.join(BIN, "cablesim"), "run", scene_path, "--out", csv_path],
                       check=True, stdout=subprocess.DEVNULL)
        with open(csv_path) as f:
            header = f.readline().strip().split(",")
        reference = np.loadtxt(csv_path, delimiter=",", skiprows=1)
        self.assertEqual(header, result.columns)
        np.testing.assert_array_equal(result.data, reference)
        png = os.path.join(self.tmp.name, "run.png")
        cablesim_client.plot(result, png)
        with open(png, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")

    def test_job_keeps_the_streamed_trajectory(self):
        scene = self.scene()
        streamed = cablesim_client.run(self.stub, scene)
        job_id = cablesim_client.submit(self.stub, scene)
        self.assertTrue(job_id.startswith("j-"))
        job = cablesim_client.wait(self.stub, job_id, timeout=60)
        self.assertEqual(job.state, cablesim_client.service_pb2.SUCCEEDED)
        kept = cablesim_client.job_result(self.stub, job_id)
        np.testing.assert_array_equal(kept.data, streamed.data)
        self.assertEqual(kept.summary.frames, 101)

    def test_invalid_scene_names_the_field(self):
        scene = self.scene()
        scene.cables[0].length = -1
        with self.assertRaises(grpc.RpcError) as caught:
            cablesim_client.run(self.stub, scene)
        self.assertEqual(caught.exception.code(), grpc.StatusCode.INVALID_ARGUMENT)
        self.assertTrue(caught.exception.details().startswith("cables[0].length"))


class TlsAndTokenTest(unittest.TestCase):
    """connect(tls_ca=..., token=...) against a server with TLS (a CA made
    here with openssl) and --token-file."""

    def test_tls_and_token(self):
        with tempfile.TemporaryDirectory() as tmp:
            def sh(command):
                subprocess.run(command, shell=True, cwd=tmp, check=True,
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            sh("openssl req -x509 -newkey rsa:2048 -nodes -keyout ca.key -out ca.pem -days 1 "
               "-subj /CN=cablesim-test-ca")
            sh("openssl req -newkey rsa:2048 -nodes -keyout server.key -out server.csr "
               "-subj /CN=localhost")
            with open(os.path.join(tmp, "ext"), "w") as f:
                f.write("subjectAltName=DNS:localhost,IP:127.0.0.1\n")
            sh("openssl x509 -req -in server.csr -CA ca.pem -CAkey ca.key -CAcreateserial "
               "-out server.pem -days 1 -extfile ext")
            token = "tok-python-0123456789"
            with open(os.path.join(tmp, "tokens"), "w") as f:
                f.write(token + " py\n")
            with open(os.path.join(tmp, "my-token"), "w") as f:
                f.write("# mine\n" + token + "\n")
            port_file = os.path.join(tmp, "port")
            os.mkdir(os.path.join(tmp, "data"))
            server = subprocess.Popen(
                [os.path.join(BIN, "cablesim-server"), "--listen=127.0.0.1:0",
                 "--data-dir=" + os.path.join(tmp, "data"), "--port-file=" + port_file,
                 "--tls-cert=" + os.path.join(tmp, "server.pem"),
                 "--tls-key=" + os.path.join(tmp, "server.key"),
                 "--token-file=" + os.path.join(tmp, "tokens")])
            try:
                while not os.path.exists(port_file):
                    if server.poll() is not None:
                        raise RuntimeError("cablesim-server exited with %d" % server.returncode)
                    time.sleep(0.01)
                with open(port_file) as f:
                    address = "localhost:" + f.read().strip()
                ca = os.path.join(tmp, "ca.pem")
                request = cablesim_client.service_pb2.GetServerInfoRequest()
                stub = cablesim_client.connect(
                    address, tls_ca=ca,
                    token=cablesim_client.read_token(os.path.join(tmp, "my-token")))
                self.assertTrue(stub.GetServerInfo(request, timeout=30).version)
                with self.assertRaises(grpc.RpcError) as raised:
                    cablesim_client.connect(address, tls_ca=ca).GetServerInfo(request, timeout=30)
                self.assertEqual(raised.exception.code(), grpc.StatusCode.UNAUTHENTICATED)
            finally:
                server.terminate()
                server.wait(timeout=30)


if __name__ == "__main__":
    unittest.main()
