"""Installs the cablesim package into a fresh virtual environment and runs
it against a live cablesim-server (CTest python_package_slow_test).

Outside the venv (Debian's /usr/bin/python3): copies client/python and proto/
to a temporary source tree made read-only (the build must write nothing
there), makes `python3 -m venv --system-site-packages`, installs with `pip
install --no-index --no-build-isolation` (no package index: the dependencies
must come from Debian's python3-grpcio, python3-protobuf, python3-numpy and
python3-matplotlib; the build needs no package, client/python/build_backend),
then runs this file again with the venv's python, from the temporary
directory, with PYTHONPATH cleared: there, the tests below see only the
installed package.

Then the same install with a Python that is not Debian's
($CABLESIM_OTHER_PYTHON, else the first python3 on PATH outside /usr/bin and
/bin, 3.9 or later; none: said, not failed) into a venv of its own, with
--no-deps: such a Python usually lacks wheel, grpcio, protobuf and numpy, so
it checks the install (files, metadata, generated modules) and the parts that
need none of them (`import cablesim`, cablesim.errors).
"""

import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import unittest

SOURCE = os.environ["CABLESIM_SOURCE_DIR"]
BIN = os.environ["CABLESIM_BIN_DIR"]
INNER = "CABLESIM_PACKAGE_TEST_VENV"


def read_only_tree(tmp):
    """client/python and proto/ copied under tmp/src, then made read-only."""
    tree = os.path.join(tmp, "src")
    shutil.copytree(os.path.join(SOURCE, "client", "python"),
                    os.path.join(tree, "client", "python"),
                    ignore=shutil.ignore_patterns("build", "*.egg-info", "__pycache__"))
    shutil.copytree(os.path.join(SOURCE, "proto"), os.path.join(tree, "proto"))
    for directory, dirs, files in os.walk(tree):
        for name in files:
            os.chmod(os.path.join(directory, name), 0o444)
        os.chmod(directory, 0o555)
    return tree


def make_writable(tree):
    for directory, dirs, files in os.walk(tree):
        os.chmod(directory, 0o755)


def other_python():
    """A Python 3.9+ that is not Debian's, or None."""
    candidates = [os.environ.get("CABLESIM_OTHER_PYTHON")]
    for directory in os.environ.get("PATH", "").split(os.pathsep):
        if os.path.realpath(directory) not in ("/usr/bin", "/bin", "/usr/local/bin"):
            candidates.append(os.path.join(directory, "python3"))
    for candidate in candidates:
        if not candidate or not os.access(candidate, os.X_OK):
            continue
        r = subprocess.run([candidate, "-c", "import sys; print(sys.version_info >= (3, 9), "
                            "sys.prefix)"], capture_output=True, text=True)
        if r.returncode == 0 and r.stdout.startswith("True") and "/usr" != r.stdout.split()[1]:
            return candidate
    return None


# Run by the other Python from its venv: what needs neither grpc nor numpy.
OTHER_PYTHON_CHECK = r"""
import importlib.util, os, sys
import cablesim
from importlib import metadata
assert cablesim.__version__ == metadata.version("cablesim") == os.environ["CABLESIM_VERSION"]
assert cablesim.__file__.startswith(sys.prefix), cablesim.__file__
for module in ("cablesim.v1.scene_pb2", "cablesim.v1.service_pb2", "cablesim.v1.service_pb2_grpc"):
    assert importlib.util.find_spec(module) is not None, module
from cablesim.errors import scene_error_from_json_parse
e = scene_error_from_json_parse('Failed to parse cables field: Message type "cablesim.v1.Cable" '
                                'has no field named "youngsModulos" at "Scene.cables[0]".', "scene")
assert isinstance(e, cablesim.Error) and isinstance(e, ValueError)
assert (e.code, e.field) == ("INVALID_ARGUMENT", "cables[0].youngsModulos"), (e.code, e.field)
e = scene_error_from_json_parse("Failed to parse solver field: Failed to parse initialState "
                                "field: Invalid enum value X at Scene.solver.initialState..")
assert e.field == "solver.initial_state", e.field
def present(name):
    try:
        return importlib.util.find_spec(name) is not None
    except ImportError:
        return False
have = [m for m in ("grpc", "google.protobuf", "numpy") if present(m)]
print("other python %s: installed cablesim %s; has %s" % (
    sys.version.split()[0], cablesim.__version__, ", ".join(have) or "none of grpc, protobuf, numpy"))
"""


def install_with_other_python(tmp, env):
    python = other_python()
    if python is None:
        print("other python: none found (set CABLESIM_OTHER_PYTHON): not checked", flush=True)
        return 0
    tree = read_only_tree(os.path.join(tmp, "other"))
    venv = os.path.join(tmp, "other-venv")
    subprocess.run([python, "-m", "venv", venv], check=True)
    venv_python = os.path.join(venv, "bin", "python")
    started = time.monotonic()
    r = subprocess.run([venv_python, "-m", "pip", "install", "--no-index", "--no-build-isolation",
                        "--no-deps", "--quiet", os.path.join(tree, "client", "python")],
                       env=env, cwd=tmp)
    print("other python %s: pip install %.1f s, exit %d" % (python, time.monotonic() - started,
                                                            r.returncode), flush=True)
    make_writable(tree)
    if r.returncode != 0:
        return r.returncode
    return subprocess.run([venv_python, "-c", OTHER_PYTHON_CHECK], env=env, cwd=tmp).returncode


def install_and_rerun():
    with tempfile.TemporaryDirectory() as tmp:
        tree = read_only_tree(tmp)
        venv = os.path.join(tmp, "venv")
        subprocess.run([sys.executable, "-m", "venv", "--system-site-packages", venv], check=True)
        python = os.path.join(venv, "bin", "python")
        env = dict(os.environ)
        env.pop("PYTHONPATH", None)
        env["PIP_NO_INDEX"] = "1"  # offline: nothing may be downloaded
        env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
        started = time.monotonic()
        subprocess.run([python, "-m", "pip", "install", "--no-index", "--no-build-isolation",
                        "--quiet", os.path.join(tree, "client", "python")],
                       check=True, env=env, cwd=tmp)
        print("pip install: %.1f s" % (time.monotonic() - started), flush=True)
        # The installed package must not depend on the copied sources.
        make_writable(tree)
        shutil.rmtree(tree)
        other = install_with_other_python(tmp, env)
        if other != 0:
            return other
        env[INNER] = venv
        # Run from a copy: beside the original, the script's own directory
        # (client/python) would come first on sys.path.
        script = os.path.join(tmp, "check_installed_package.py")
        shutil.copy(os.path.abspath(__file__), script)
        shutil.copy(os.path.join(os.path.dirname(os.path.abspath(__file__)), "live_server.py"), tmp)
        return subprocess.run([python, script], env=env, cwd=tmp).returncode


if os.environ.get(INNER) is None:
    sys.exit(install_and_rerun())

import grpc  # noqa: E402
import numpy as np  # noqa: E402
from google.protobuf import json_format, text_format  # noqa: E402

import cablesim  # noqa: E402
from live_server import start_server  # noqa: E402

PENDULUM = os.path.join(SOURCE, "scenes", "falling-pendulum.json")


def pendulum(duration=0.1):
    """The falling pendulum as a dict, enums by name, shortened."""
    scene = cablesim.scene_to_dict(cablesim.load_scene(PENDULUM))
    scene["solver"]["duration"] = duration
    return scene


class PackageTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.server, port = start_server(cls.tmp.name, "--workers=2")
        cls.client = cablesim.Client("127.0.0.1:%d" % port)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.server.terminate()
        cls.server.wait(timeout=30)
        cls.tmp.cleanup()

    def cli_csv(self, scene_dict):
        """The trajectory of `cablesim run` (its own in-process engine) as
        (header, array): the reference the streamed doubles must equal."""
        path = os.path.join(self.tmp.name, "reference.json")
        csv = os.path.join(self.tmp.name, "reference.csv")
        with open(path, "w") as f:
            f.write(json_format.MessageToJson(cablesim.load_scene(scene_dict)))
        subprocess.run([os.path.join(BIN, "cablesim"), "run", path, "--out", csv], check=True,
                       stdout=subprocess.DEVNULL)
        with open(csv) as f:
            header = f.readline().strip().split(",")
        return header, np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)

    def test_installed_with_generated_modules_and_declared_dependencies(self):
        venv = os.path.realpath(os.environ[INNER])
        for module in (cablesim, cablesim.client, __import__("cablesim.v1.service_pb2_grpc").v1):
            self.assertTrue(os.path.realpath(module.__file__).startswith(venv), module.__file__)
        from importlib import metadata
        self.assertEqual(metadata.version("cablesim"), os.environ["CABLESIM_VERSION"])
        self.assertEqual(cablesim.__version__, os.environ["CABLESIM_VERSION"])
        required = {re.match(r"[A-Za-z0-9_.-]+", r).group()
                    for r in metadata.requires("cablesim") if "extra ==" not in r}
        self.assertEqual(required, {"grpcio", "protobuf", "numpy", "matplotlib"})
        self.assertEqual(self.client.info().version, os.environ["CABLESIM_VERSION"])

    def test_run_from_dict_json_and_text_format_equals_the_cli(self):
        scene = pendulum()
        header, reference = self.cli_csv(scene)
        text_path = os.path.join(self.tmp.name, "pendulum.txtpb")
        with open(text_path, "w") as f:
            f.write(text_format.MessageToString(cablesim.load_scene(scene)))
        json_path = os.path.join(self.tmp.name, "pendulum.json")
        with open(json_path, "w") as f:
            f.write(json_format.MessageToJson(cablesim.load_scene(scene)))
        for source in (scene, json_path, text_path):
            result = self.client.run(source)
            self.assertEqual(result.summary.status, "ok")
            self.assertEqual(result.summary["integrator"], scene["solver"]["integrator"])
            self.assertEqual(result.columns, header)
            # 0.1 s every 1 ms; t, 9 tip, 6 totals and energy.damped, 4 energies of the
            # cable, the loads'
            self.assertEqual(result.data.shape, (101, 1 + 9 + 7 + 4 + 1))
            # Same engine, same scene: identical doubles (the CSV has 17 digits).
            np.testing.assert_array_equal(result.data, reference)
            np.testing.assert_array_equal(result["tip.y"], reference[:, header.index("tip.y")])
            np.testing.assert_array_equal(result.position("tip")[:, 1], result["tip.y"])
        self.assertEqual(result.info.probe_names, ["tip"])

    def test_submit_wait_result_and_energy(self):
        scene = pendulum()
        streamed = self.client.run(scene)
        job_id = self.client.submit(scene)
        job = self.client.wait(job_id, timeout=120)
        self.assertEqual(job.state, "SUCCEEDED")  # enums as names
        self.assertTrue(job.finished)
        self.assertEqual(job.summary.frames, 101)
        kept = self.client.result(job_id)
        np.testing.assert_array_equal(kept.data, streamed.data)
        for energy in (self.client.energy(job_id), self.client.energy(job)):
            np.testing.assert_array_equal(energy.t, streamed.t)
            np.testing.assert_array_equal(energy.total, streamed["energy.total"])
            np.testing.assert_array_equal(energy.kinetic, streamed["energy.kinetic"])
            self.assertEqual(energy.report.initial, streamed["energy.total"][0])
            self.assertEqual(energy.report.max, streamed["energy.total"].max())
        from_scene = self.client.energy(scene)
        np.testing.assert_array_equal(from_scene.total, streamed["energy.total"])

    def test_sweep_table_matches_single_runs(self):
        base = pendulum(0.05)
        steps = [1e-3, 5e-4]
        table = self.client.sweep(base, {"cables[0].elements": [4, 6], "solver.step": steps},
                                  name="py", timeout=300)
        self.assertEqual(table.items, 4)
        self.assertEqual(table.states, ["SUCCEEDED"] * 4)
        self.assertEqual(table.axis_paths, ["cables[0].elements", "solver.step"])
        np.testing.assert_array_equal(table.axis_values,
                                      [[4, 1e-3], [4, 5e-4], [6, 1e-3], [6, 5e-4]])
        # Item 3 (last axis fastest) run on its own: the same last frame.
        single = dict(base, cables=[dict(base["cables"][0], elements=6)],
                      solver=dict(base["solver"], step=5e-4))
        alone = self.client.run(single)
        self.assertEqual(table.final_columns, alone.columns)
        np.testing.assert_array_equal(table.final[3], alone.data[-1])
        self.assertEqual(table.summaries[3].steps, alone.summary.steps)
        columns = table.table()
        self.assertEqual(list(columns)[:5], ["index", "job_id", "state", "cables[0].elements",
                                             "solver.step"])
        try:
            import pandas  # noqa: F401
        except ImportError:
            with self.assertRaisesRegex(ImportError, "pandas"):
                table.to_pandas()
            return
        frame = table.to_pandas()
        self.assertEqual(frame.shape[0], 4)
        self.assertEqual(frame["final.tip.y"].iloc[3], alone["tip.y"][-1])
        np.testing.assert_array_equal(alone.to_pandas()["tip.y"].to_numpy(), alone["tip.y"])

    def test_errors_name_the_field(self):
        scene = pendulum()
        scene["cables"][0]["length"] = -1
        with self.assertRaises(cablesim.Error) as caught:
            self.client.run(scene)
        self.assertEqual(caught.exception.code, "INVALID_ARGUMENT")
        self.assertEqual(caught.exception.field, "cables[0].length")
        with self.assertRaises(cablesim.Error) as caught:
            self.client.job("j-doesnotexist")
        self.assertEqual(caught.exception.code, "NOT_FOUND")
        with self.assertRaisesRegex(ValueError, "lenght"):
            cablesim.load_scene({"cables": [{"lenght": 1}]})
        # A typo found by the package, in the scene files' names: a dict, JSON
        # text (camelCase parents come back snake_case), a text-format file.
        typo = pendulum()
        typo["cables"][0]["youngs_modulos"] = 1e6
        typo_text = '{"initialVelocity": {"linearr": {}}}'
        text_path = os.path.join(self.tmp.name, "typo.txtpb")
        with open(text_path, "w") as f:
            f.write('name: "t"\ncables {\n  youngs_modulos: 1\n}\n')
        for source, field in ((typo, "cables[0].youngs_modulos"),
                              (typo_text, "initial_velocity.linearr"),
                              ({"solver": {"initial_state": "NOPE"}}, "solver.initial_state"),
                              (text_path, "youngs_modulos")):
            with self.assertRaises(cablesim.Error) as caught:
                self.client.run(source)
            self.assertEqual((caught.exception.code, caught.exception.field),
                             ("INVALID_ARGUMENT", field), caught.exception.details)
        with self.assertRaises(FileNotFoundError):
            cablesim.load_scene(os.path.join(self.tmp.name, "missing.json"))
        self.assertFalse(self.client.validate(scene).valid)
        self.assertEqual(self.client.validate(pendulum()).model.probe_names, ["tip"])


    def test_progress_and_times(self):
        calls = []
        scene = pendulum(0.1)
        self.client.run(scene, progress=lambda done, total: calls.append((done, total)))
        self.assertTrue(calls)
        self.assertEqual(calls[-1], (0.1, 0.1))  # the last frame's time, of the duration
        self.assertEqual([c[0] for c in calls], sorted(c[0] for c in calls))
        items = []
        self.client.sweep(pendulum(0.02), {"solver.step": [1e-3, 5e-4]},
                          progress=lambda done, total: items.append((done, total)))
        self.assertEqual(items[-1], (2, 2))
        job_id = self.client.submit(scene)
        seen = []
        job = self.client.wait(job_id, progress=lambda done, total: seen.append(total))
        self.assertTrue(all(total == 0.1 for total in seen), seen)
        import datetime
        now = datetime.datetime.now(datetime.timezone.utc)
        self.assertIsInstance(job.created, datetime.datetime)
        self.assertLessEqual(job.created, job.started)
        self.assertLessEqual(job.started, job.finished_at)
        self.assertLess(abs((now - job.finished_at).total_seconds()), 600)
        self.assertEqual(round(job.created.timestamp() * 1000), job.created_unix_ms)


if __name__ == "__main__":
    unittest.main()
