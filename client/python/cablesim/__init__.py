"""cablesim: the Python client of the cablesim service (cablesim-server).

    import cablesim
    with cablesim.Client("127.0.0.1:50051") as client:
        result = client.run("scenes/falling-pendulum.json")   # numpy arrays
        job_id = client.submit({"name": "x", ...})            # a dict scene
        client.wait(job_id).state                             # "SUCCEEDED"
        table = client.sweep(scene, {"solver.step": [1e-4, 5e-5]})
    with cablesim.couple("127.0.0.1:50051", "floater.json", x0) as session:
        forces = session.step(0.05, x1, v1)                   # a coupling step

The gRPC modules (cablesim.v1.scene_pb2, service_pb2, service_pb2_grpc) are
generated from proto/cablesim/v1 when the package is built (setup.py).
"""

# In the source tree (PYTHONPATH=build/python:client/python), cablesim.v1 is
# the build directory's generated modules: let this package span both.
__path__ = __import__("pkgutil").extend_path(__path__, __name__)

__version__ = "0.15.0"

# The names below import grpc, protobuf and numpy when first used (PEP 562),
# so that `import cablesim` and cablesim.errors work without them.
_LAZY = {
    "animate": "cablesim.animation",
    "Client": "cablesim.client", "open_channel": "cablesim.client", "read_token": "cablesim.client",
    "couple": "cablesim.coupling", "CoupleSession": "cablesim.coupling",
    "Energy": "cablesim.results", "Job": "cablesim.results", "Record": "cablesim.results",
    "Result": "cablesim.results", "SweepResult": "cablesim.results", "load_csv": "cablesim.results",
    "load_scene": "cablesim.scenes", "scene_to_dict": "cablesim.scenes",
}

from cablesim.errors import Error, SceneError  # noqa: E402


def __getattr__(name):
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError("module 'cablesim' has no attribute %r" % name)
    import importlib
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


__all__ = ["animate", "Client", "couple", "CoupleSession", "Energy", "Error", "Job", "Record",
           "Result", "SceneError", "SweepResult", "load_csv", "load_scene", "open_channel", "read_token", "scene_to_dict"]
