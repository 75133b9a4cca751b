#!/usr/bin/python3
"""A coupling step from a Python host (cablesim.couple) against a local
cablesim-server: the three-line buoy with its buoy replaced by the host
(as bench/server_couple_bench.cc), driven 1 m in surge and heave over 10 s
at a coupling step of 0.05 s. Prints per step: the wall time, the host
process's CPU time (Python's gRPC and protobuf) and the server's CPU time
(the physics and the server's gRPC), from /proc.

Usage (from the source tree, after building cablesim-server and
cablesim_python):
  PYTHONPATH=build/python:client/python bench/couple_python_bench.py build/bin [STEPS]
"""

import json
import math
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

import cablesim

HERE = os.path.dirname(os.path.abspath(__file__))


def coupled_buoy(duration):
    """The scene, and the fairleads where the buoy (unrotated) holds them."""
    with open(os.path.join(HERE, "..", "scenes", "mooring-three-line-buoy.json")) as f:
        scene = json.load(f)
    centre = np.array([scene["bodies"][0]["position"].get(a, 0.0) for a in "xyz"])
    points = []
    for joint in scene["joints"]:
        if "b" in joint:
            points.append(centre + [joint["b"]["point"].get(a, 0.0) for a in "xyz"])
            del joint["b"]
            joint["coupled"] = True
    scene.pop("bodies", None)
    scene["probes"] = [p for p in scene.get("probes", []) if "body" not in p]
    scene["solver"]["duration"] = duration
    return scene, np.array(points)


def server_cpu_seconds(pid):
    with open("/proc/%d/stat" % pid) as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def main():
    bin_dir = sys.argv[1]
    steps = int(sys.argv[2]) if len(sys.argv) > 2 else 1000
    dt, omega = 0.05, 2 * math.pi / 10
    with tempfile.TemporaryDirectory() as tmp:
        port_file = os.path.join(tmp, "port")
        server = subprocess.Popen([os.path.join(bin_dir, "cablesim-server"),
                                   "--listen=127.0.0.1:0", "--data-dir=" + tmp,
                                   "--port-file=" + port_file],
                                  stderr=subprocess.DEVNULL)
        try:
            while not os.path.exists(port_file) or not open(port_file).read().strip():
                if server.poll() is not None:
                    sys.exit("cablesim-server exited with %d" % server.returncode)
                time.sleep(0.01)
            address = "127.0.0.1:" + open(port_file).read().strip()
            scene, x0 = coupled_buoy(steps * dt + 1)
            with cablesim.couple(address, scene, x0) as session:
                wall0, cpu0, srv0 = time.perf_counter(), time.process_time(), \
                    server_cpu_seconds(server.pid)
                for k in range(1, steps + 1):
                    s = math.sin(omega * k * dt)
                    c = omega * math.cos(omega * k * dt)
                    session.step(dt, x0 + [s, 0, s], np.tile([c, 0, c], (3, 1)))
                wall = time.perf_counter() - wall0
                cpu = time.process_time() - cpu0
                srv = server_cpu_seconds(server.pid) - srv0
            print("%d coupling steps of %.2f s: per step %.0f us wall, %.0f us host CPU "
                  "(Python), %.0f us server CPU (physics and gRPC); load average %.1f"
                  % (steps, dt, 1e6 * wall / steps, 1e6 * cpu / steps, 1e6 * srv / steps,
                     os.getloadavg()[0]))
        finally:
            server.terminate()
            server.wait(timeout=30)


if __name__ == "__main__":
    main()
