"""Runs the Python client against a live cablesim-server on a loopback port
and compares the streamed arrays with the CSV of `cablesim run` (the same
engine in another process: the doubles must be identical)."""

import os
import subprocess
import sys
import tempfile
import unittest

import grpc
import numpy as np

import cablesim_client
from live_server import start_server

SOURCE = os.environ["CABLESIM_SOURCE_DIR"]
BIN = os.environ["CABLESIM_BIN_DIR"]


class ClientTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.server, port = start_server(cls.tmp.name, "--workers=1")
        cls.address = "127.0.0.1:%d" % port
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
        # 0.1 s every 1 ms; t, 9 tip, 6 totals and energy.damped, 4 for the cable, loads.
        self.assertEqual(result.data.shape, (101, 1 + 9 + 7 + 4 + 1))
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

    def test_reactions_tensions_and_the_csv_loader(self):
        """Reactions and tensions by name, and load_csv reading the CLI's CSV
        into the same Result (the numbers are checked against closed forms
        in tests/joint_reactions_test.cc and cable_tension_test.cc)."""
        import cablesim
        scene = self.scene()
        scene.solver.duration = 0.02
        scene.joints[0].name = "pin"
        scene.output.reactions = True
        scene.output.tension = True
        result = cablesim_client.run(self.stub, scene)
        self.assertEqual(result.summary.status, "ok")
        self.assertEqual(list(result.info.joint_names), ["pin"])
        force = result.reaction("pin")
        self.assertEqual(force.shape, (21, 3))
        np.testing.assert_array_equal(force, result.reaction(0))
        np.testing.assert_array_equal(force[:, 1], result["joints[0].fy"])
        # The pin holds the beam up while it falls: the vertical force on
        # the beam is upward and below the beam's weight.
        weight = -scene.gravity.y * scene.cables[0].density * scene.cables[0].area \
            * scene.cables[0].length if scene.cables[0].area else None
        self.assertTrue(np.all(force[1:, 1] > 0), force[:, 1])
        if weight:
            self.assertTrue(np.all(force[1:, 1] < weight), (force[:, 1], weight))
        # The free tip carries no axial force.
        self.assertLess(np.max(np.abs(result.tension("tip"))), 1e-6 * np.max(np.abs(force)))
        with self.assertRaises(KeyError):
            result.reaction("no-such-joint")
        scene_path = os.path.join(self.tmp.name, "reactions.json")
        csv_path = os.path.join(self.tmp.name, "reactions.csv")
        from google.protobuf import json_format
        with open(scene_path, "w") as f:
            f.write(json_format.MessageToJson(scene))
        subprocess.run([os.path.join(BIN, "cablesim"), "run", scene_path, "--out", csv_path],
                       check=True, stdout=subprocess.DEVNULL)
        loaded = cablesim.load_csv(csv_path)
        self.assertEqual(loaded.columns, result.columns)
        np.testing.assert_array_equal(loaded.data, result.data)
        np.testing.assert_array_equal(loaded.reaction(0), force)

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

    def test_shape_animates_to_a_gif(self):
        # The sample scene with output.shape (two cables, 13 nodes), 0.2 s:
        # 11 frames; drawn at 5 chosen times, then at every frame.
        scene = cablesim_client.load_scene(
            os.path.join(SOURCE, "scenes", "kinked-string-shape.json"))
        scene.solver.duration = 0.2
        result = cablesim_client.run(self.stub, scene)
        self.assertEqual(result.summary.status, "ok")
        string, tail = result.cable_nodes(0), result.cable_nodes(1)
        self.assertEqual(string.shape, (11, 9, 3))
        self.assertEqual(tail.shape, (11, 4, 3))
        # The probe at the kink (s = 1) is node 4 of the string.
        np.testing.assert_array_equal(string[:, 4, 0], result.column("kink.x"))
        np.testing.assert_array_equal(string[:, 4, 1], result.column("kink.y"))
        try:
            from PIL import Image
            import matplotlib  # noqa: F401
        except ImportError as e:
            self.skipTest("GIF needs Debian's python3-matplotlib and python3-pil: %s" % e)
        gif = os.path.join(self.tmp.name, "shape.gif")
        written = cablesim_client.animate(result, gif, times=[0, 0.05, 0.1, 0.15, 0.2])
        self.assertEqual(written, 5)
        with Image.open(gif) as image:
            self.assertEqual(image.format, "GIF")
            self.assertEqual(image.n_frames, 5)
        cablesim_client.animate(result, gif)
        with Image.open(gif) as image:
            self.assertEqual(image.n_frames, 11)
        # Without the shape there is nothing to draw.
        plain = cablesim_client.run(self.stub, self.scene())
        with self.assertRaises(ValueError):
            plain.cable_nodes(0)

    def test_views_tensions_shape_csv_and_scene_overlays(self):
        """A mooring read as its engineer reads it: the path in the x-z
        plane with the fairlead tensions beside it; the CLI's CSV and shape
        CSV loaded into the same Result as the service streams (every
        number identical); the animation with the buoy, the seabed and the
        water line."""
        import cablesim
        from cablesim.animation import scene_overlays
        from google.protobuf import json_format
        scene = cablesim_client.load_scene(
            os.path.join(SOURCE, "scenes", "mooring-three-line-buoy.json"))
        scene.solver.duration = 0.5
        scene.solver.output_interval = 0.1
        scene.output.shape = True
        scene.output.tension = True
        result = cablesim_client.run(self.stub, scene)
        self.assertEqual(result.summary.status, "ok")
        scene_path = os.path.join(self.tmp.name, "buoy.json")
        csv_path = os.path.join(self.tmp.name, "buoy.csv")
        shape_path = os.path.join(self.tmp.name, "buoy.shape.csv")
        with open(scene_path, "w") as f:
            f.write(json_format.MessageToJson(scene, preserving_proto_field_name=True))
        subprocess.run([os.path.join(BIN, "cablesim"), "run", scene_path, "--out", csv_path,
                        "--shape", shape_path], check=True, stdout=subprocess.DEVNULL)
        loaded = cablesim.load_csv(csv_path, shape=shape_path)
        self.assertEqual(loaded.columns, result.columns)
        np.testing.assert_array_equal(loaded.data, result.data)
        np.testing.assert_array_equal(loaded.cable_nodes(2), result.cable_nodes(2))
        self.assertEqual(loaded.info.cable_names, ["cables[0]", "cables[1]", "cables[2]"])
        with self.assertRaises(ValueError):  # not a shape CSV
            cablesim.load_csv(csv_path, shape=csv_path)
        # The overlays from the scene: gravity along z, the bed 50 m below
        # the still water level 0, the buoy at its probe.
        overlays = scene_overlays(scene_path, "xz")
        self.assertEqual((overlays["up"], overlays["seabed"], overlays["water"]), ("z", -50.0, 0.0))
        self.assertEqual(overlays["bodies"], [("buoy", "buoy")])
        self.assertEqual(scene_overlays(scene, ("x", "y"))["seabed"], None)
        try:
            from PIL import Image
            import matplotlib  # noqa: F401
        except ImportError as e:
            self.skipTest("plots need Debian's python3-matplotlib and python3-pil: %s" % e)
        png = os.path.join(self.tmp.name, "buoy.png")
        loaded.plot(png, probe="buoy", view="xz", tension=True)
        with open(png, "rb") as f:
            self.assertEqual(f.read(8), b"\x89PNG\r\n\x1a\n")
        with self.assertRaises(ValueError):
            loaded.plot(png, view="xx")
        gif = os.path.join(self.tmp.name, "buoy.gif")
        self.assertEqual(cablesim.animate(loaded, gif, plane="xz", scene=scene_path), 6)
        with Image.open(gif) as image:
            self.assertEqual(image.n_frames, 6)

    def test_shape_animates_to_an_mp4_with_ffmpeg(self):
        import shutil
        if shutil.which("ffmpeg") is None:
            self.skipTest("MP4 needs Debian's ffmpeg (not installed)")
        scene = cablesim_client.load_scene(
            os.path.join(SOURCE, "scenes", "kinked-string-shape.json"))
        scene.solver.duration = 0.1
        result = cablesim_client.run(self.stub, scene)
        mp4 = os.path.join(self.tmp.name, "shape.mp4")
        self.assertEqual(cablesim_client.animate(result, mp4), 6)
        with open(mp4, "rb") as f:
            self.assertEqual(f.read(12)[4:8], b"ftyp")

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
            os.chmod(os.path.join(tmp, "tokens"), 0o600)  # the server refuses others' reading
            with open(os.path.join(tmp, "my-token"), "w") as f:
                f.write("# mine\n" + token + "\n")
            os.mkdir(os.path.join(tmp, "data"))
            server, port = start_server(
                os.path.join(tmp, "data"), "--tls-cert=" + os.path.join(tmp, "server.pem"),
                "--tls-key=" + os.path.join(tmp, "server.key"),
                "--token-file=" + os.path.join(tmp, "tokens"))
            try:
                address = "localhost:%d" % port
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
