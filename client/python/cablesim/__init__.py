"""cablesim: the Python client of the cablesim service (cablesim-server).

    import cablesim
    with cablesim.Client("127.0.0.1:50051") as client:
        result = client.run("scenes/falling-pendulum.json")   # numpy arrays
        job_id = client.submit({"name": "x", ...})            # a dict scene
        client.wait(job_id).state                             # "SUCCEEDED"
        table = client.sweep(scene, {"solver.step": [1e-4, 5e-5]})

The gRPC modules (cablesim.v1.scene_pb2, service_pb2, service_pb2_grpc) are
generated from proto/cablesim/v1 when the package is built (setup.py).
"""

# In the source tree (PYTHONPATH=build/python:client/python), cablesim.v1 is
# the build directory's generated modules: let this package span both.
__path__ = __import__("pkgutil").extend_path(__path__, __name__)

__version__ = "0.15.0"

from cablesim.animation import animate  # noqa: E402
from cablesim.client import Client, Error, open_channel, read_token  # noqa: E402
from cablesim.results import Energy, Job, Record, Result, SweepResult  # noqa: E402
from cablesim.scenes import load_scene, scene_to_dict  # noqa: E402

__all__ = ["animate", "Client", "Energy", "Error", "Job", "Record", "Result", "SweepResult", "load_scene",
           "open_channel", "read_token", "scene_to_dict"]
