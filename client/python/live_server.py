"""The tests' cablesim-server: the build's binary ($CABLESIM_BIN_DIR) on a
free loopback port."""

import os
import subprocess
import time


def start_server(data_dir, *flags):
    """Starts cablesim-server with its jobs in `data_dir` (which also takes
    its port file) and `flags`; returns (process, port) once it listens.
    Waits until the server has written its port, or exited: no time limit
    that a busy machine could exceed."""
    port_file = os.path.join(data_dir, "port")
    server = subprocess.Popen(
        [os.path.join(os.environ["CABLESIM_BIN_DIR"], "cablesim-server"), "--listen=127.0.0.1:0",
         "--data-dir=" + data_dir, "--port-file=" + port_file] + list(flags))
    while not os.path.exists(port_file):
        if server.poll() is not None:
            raise RuntimeError("cablesim-server exited with %d" % server.returncode)
        time.sleep(0.01)
    with open(port_file) as f:
        return server, int(f.read().strip())
