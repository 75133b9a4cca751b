"""The Couple stream from Python (cablesim.couple) against a live
cablesim-server on a loopback port (CTest python_couple_test).

The coupled floater: a floater (point mass m, the buoyancy of a vertical
cylinder rho g A s(z), linear in its draft s: a linear hydrostatic
stiffness rho g A; linear damping c; a harmonic force in x and z) is
integrated here, by the host, with velocity Verlet (the damping implicit),
and moored by the three lines of tests/data/couple_floater_coupled.json
through Couple (the forces each step returns: their mean over the step).
The reference is the same floater modelled as a cablesim body in one scene
(tests/data/couple_floater_body.json), run by the same server (Run): its
step, 2.5 ms, is converged (tests/couple_floater_test.c: the run at
0.625 ms differs by 1e-5 m). The scheme is explicit (the lines see the
host's position at the step's end, reached linearly; the host takes the
lines' mean force over the step as the force at its end): first order. The
largest distance from the reference in the plane of the forcing (x, z)
over the frames (every 0.2 s for 5 s) at coupling steps 0.05, 0.025 and
0.0125 s must fall by at least 2^0.8 per halving (0.8: the C test's margin
under the first order for the pre-asymptotic range; measured 1.26 and 1.23
there), and the finest must be below 1 % of the reference's excursion.
The C program (couple_floater_test) measured 4.3e-3, 1.8e-3 and 7.7e-4 m:
the same session, so the same numbers are expected here within rounding.

Then each bad input: the reply names the field and the session stays
usable; the per-client stream limit, a token, and the stall timeout.
"""

import math
import os
import tempfile
import time
import unittest

import numpy as np

import cablesim
from cablesim.v1 import service_pb2
from live_server import start_server

SOURCE = os.environ["CABLESIM_SOURCE_DIR"]
COUPLED = os.path.join(SOURCE, "tests", "data", "couple_floater_coupled.json")
BODY = os.path.join(SOURCE, "tests", "data", "couple_floater_body.json")

MASS, DAMPING, RHO, G = 20000.0, 20000.0, 1025.0, 9.81
DIAMETER, HEIGHT = 4.0, 4.0
COMPARE_UNTIL = 5.0  # s: later the symmetric motion loses its symmetry (the C test)


def host_force(x, t):
    """Buoyancy, gravity and the external force on the floater (not the
    lines', not the damping) at position x and time t."""
    area = math.pi * DIAMETER ** 2 / 4
    s = min(max(HEIGHT / 2 - x[2], 0.0), HEIGHT)
    return np.array([20000.0 * math.sin(2 * math.pi * 0.1 * t), 0.0,
                     RHO * G * area * s - MASS * G + 20000.0 * math.sin(2 * math.pi * 0.15 * t)])


class CoupleTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        # One stream per client: the sessions below must free theirs when
        # closed (and the limit test needs it).
        cls.server, port = start_server(cls.tmp.name, "--workers=1", "--max-streams-per-peer=1")
        cls.address = "127.0.0.1:%d" % port
        cls.client = cablesim.Client(cls.address)
        reference = cls.client.run(BODY)
        assert reference.summary.status == "ok", reference.summary
        cls.ref_t = reference.t
        cls.ref_x = np.stack([reference["floater.x"], reference["floater.y"],
                              reference["floater.z"]], axis=1)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.server.terminate()
        cls.server.wait(timeout=30)
        cls.tmp.cleanup()

    def start(self):
        """The floater's initial position, the reference's statics, at each
        of the three fairleads."""
        return np.tile(self.ref_x[0], (3, 1))

    def coupled(self, dt):
        """The largest distance (x, z) from the reference at coupling step dt."""
        x = self.ref_x[0].copy()
        v = np.zeros(3)
        with cablesim.couple(self.address, COUPLED, self.start()) as session:
            self.assertEqual(session.points, 3)
            f = session.forces.sum(axis=0)
            t, err, frame = 0.0, 0.0, 1
            for _ in range(round(self.ref_t[-1] / dt)):
                a = (host_force(x, t) + f - DAMPING * v) / MASS
                vh = v + 0.5 * dt * a
                x = x + dt * vh
                f = session.step(dt, np.tile(x, (3, 1)), np.tile(vh, (3, 1))).sum(axis=0)
                t = session.time
                v = (vh + 0.5 * dt * (host_force(x, t) + f) / MASS) / (1 + 0.5 * dt * DAMPING / MASS)
                while (frame < len(self.ref_t) and abs(self.ref_t[frame] - t) <= 1e-9
                       and self.ref_t[frame] <= COMPARE_UNTIL):
                    err = max(err, math.hypot(x[0] - self.ref_x[frame][0],
                                              x[2] - self.ref_x[frame][2]))
                    frame += 1
            self.assertGreaterEqual(self.ref_t[frame - 1] + 1e-9, COMPARE_UNTIL)
            self.assertGreater(session.steps, 0)
        return err

    def test_coupled_floater_converges_to_the_body_in_one_scene(self):
        excursion = np.max(np.linalg.norm(self.ref_x - self.ref_x[0], axis=1))
        steps = [0.05, 0.025, 0.0125]
        errors = [self.coupled(dt) for dt in steps]
        for dt, e in zip(steps, errors):
            print("coupling step %.4f s: largest distance from the reference %.3e m" % (dt, e))
        for i in range(1, len(steps)):
            order = math.log(errors[i - 1] / errors[i]) / math.log(steps[i - 1] / steps[i])
            print("observed order %.4f -> %.4f s: %.2f" % (steps[i - 1], steps[i], order))
            self.assertGreaterEqual(order, 0.8, errors)
        print("reference excursion %.4f m" % excursion)
        self.assertLess(errors[-1], 0.01 * excursion)

    def test_lines_and_the_forces_at_rest(self):
        """At t = 0 the lines hold the floater's excess buoyancy (the
        reference's statics: the host's force and the lines' balance), and
        the fairlead nodes sit at the coupled points."""
        x0 = self.start()
        with cablesim.couple(self.client, COUPLED, x0, lines=True) as session:
            self.assertEqual(session.coupled_joints, [1, 3, 5])
            self.assertAlmostEqual(session.max_jump_m, 18.0)
            self.assertEqual(session.end_time_s, 5.0)
            lines = session.forces.sum(axis=0)
            host = host_force(x0[0], 0.0)
            # The statics' tolerance: 1e-6 of the weight.
            np.testing.assert_allclose(lines + host, 0, atol=1e-6 * MASS * G)
            self.assertEqual([name for name, _, _ in session.lines], ["line1", "line2", "line3"])
            for i, (name, nodes, tensions) in enumerate(session.lines):
                self.assertEqual(nodes.shape, (11, 3))
                np.testing.assert_allclose(nodes[-1], x0[i], atol=1e-9)
                self.assertGreater(tensions[-1], 0)
            session.step(0.05, x0 + [0.01, 0, 0])
            self.assertAlmostEqual(session.time, 0.05)
            np.testing.assert_allclose(session.lines[0][1][-1], x0[0] + [0.01, 0, 0], atol=1e-9)

    def assert_refused(self, session, field, *step):
        time_before, forces_before = session.time, session.forces.copy()
        with self.assertRaises(cablesim.Error) as raised:
            session.step(*step)
        self.assertEqual(raised.exception.code, "INVALID_ARGUMENT")
        self.assertEqual(raised.exception.field, field, raised.exception.details)
        self.assertTrue(raised.exception.details.startswith(field + ": "))
        self.assertEqual(session.time, time_before)
        np.testing.assert_array_equal(session.forces, forces_before)
        return raised.exception.details

    def test_a_coupled_body(self):
        """A coupled body (tests/data/couple_body_coupled.json: three lines
        pinned 10 m from its centre) opened turned by 0.2 rad about a tilted
        axis: its force and moment are the sum of the forces and of r x F
        of the same lines with their fairleads as coupled points
        (couple_body_points.json) placed at the body's turned points: the
        same static equilibrium, so to Newton's tolerance (1e-8 of |F|, of
        |F| r for the moment; tests/couple_body_test.c measures 1e-11).
        Then a step (the host's work booked) and each bad pose, refused
        naming the field with the session unchanged."""
        axis = np.array([0.0, 0.5, 1.0]) / math.sqrt(1.25)
        angle = 0.2
        q = np.concatenate([[math.cos(angle / 2)], math.sin(angle / 2) * axis])
        k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        rotation = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k
        body_file = os.path.join(SOURCE, "tests", "data", "couple_body_coupled.json")
        points_file = os.path.join(SOURCE, "tests", "data", "couple_body_points.json")
        with cablesim.couple(self.address, body_file, bodies=[(np.zeros(3), q)]) as session:
            self.assertEqual(session.coupled_bodies, [0])
            np.testing.assert_allclose(session.body_scene_orientations, [[1, 0, 0, 0]], atol=1e-12)
            force, moment = session.body_forces[0].copy(), session.body_moments[0].copy()
            self.assertEqual(session.host_work, 0)
            session.step(0.05, bodies=[((0.01, 0, 0), q)])
            self.assertNotEqual(session.host_work, 0)
            good = session.body_forces.copy()
            bad = [("bodies[0].orientation", [(np.zeros(3), 1.1 * q)]),
                   ("bodies[0].orientation.x", [(np.zeros(3), (1, math.nan, 0, 0))]),
                   ("bodies[0].angular_velocity.z",
                    [(np.zeros(3), q, np.zeros(3), (0, 0, math.inf))]),
                   ("bodies", [(np.zeros(3), q), (np.zeros(3), q)])]
            for field, bodies in bad:
                with self.assertRaises(cablesim.Error) as raised:
                    session.step(0.05, bodies=bodies)
                self.assertEqual(raised.exception.code, "INVALID_ARGUMENT")
                self.assertEqual(raised.exception.field, field, raised.exception.details)
                self.assertAlmostEqual(session.time, 0.05)
                np.testing.assert_array_equal(session.body_forces, good)
            session.step(0.05, bodies=[((0.02, 0, 0), q)])
            self.assertAlmostEqual(session.time, 0.1)
        base = np.array([[10 * math.cos(a), 10 * math.sin(a), 0.0]
                         for a in (0, 2 * math.pi / 3, 4 * math.pi / 3)])
        arms = base @ rotation.T
        with cablesim.couple(self.address, points_file, arms) as session:
            forces = session.forces
        scale = np.linalg.norm(forces.sum(axis=0))
        self.assertLess(np.linalg.norm(force - forces.sum(axis=0)), 1e-8 * scale)
        self.assertLess(np.linalg.norm(moment - np.cross(arms, forces).sum(axis=0)),
                        1e-8 * scale * 10)

    def test_bad_steps_name_the_field_and_leave_the_session_usable(self):
        x0 = self.start()
        with cablesim.couple(self.address, COUPLED, x0) as session:
            session.step(0.05, x0)
            four = np.vstack([x0, x0[:1]])
            self.assert_refused(session, "points", 0.05, four)  # a point that does not exist
            self.assert_refused(session, "points", 0.05, x0[:2])
            nan = x0.copy()
            nan[2, 0] = float("nan")
            details = self.assert_refused(session, "points[2].position.x", 0.05, nan)
            self.assertIn("must be finite", details)
            inf = np.zeros((3, 3))
            inf[1, 2] = float("inf")
            self.assert_refused(session, "points[1].velocity.z", 0.05, x0, inf)
            self.assertIn("backwards", self.assert_refused(session, "dt_s", -0.05, x0))
            self.assert_refused(session, "dt_s", 0.0, x0)
            self.assert_refused(session, "dt_s", float("nan"), x0)
            self.assertIn("solver.duration", self.assert_refused(session, "dt_s", 10.0, x0))
            jump = x0.copy()
            jump[0, 0] += 100
            self.assertIn("18 m allowed", self.assert_refused(session, "points[0].position", 0.05,
                                                              jump))
            # A second open gets a reply with the error, as a bad step.
            reply = session._exchange(service_pb2.CoupleRequest(open=service_pb2.CoupleOpen()))
            self.assertEqual(reply.error.code, "INVALID_ARGUMENT")
            self.assertEqual(reply.error.path, "open")
            self.assertAlmostEqual(reply.time_s, 0.05)
            # Still usable: the next steps go on from t = 0.05.
            session.step(0.05, x0 + [0.01, 0, 0])
            self.assertAlmostEqual(session.time, 0.1)
            self.assertEqual(session.forces.shape, (3, 3))

    def test_bad_opens_end_the_stream_naming_the_field(self):
        x0 = self.start()
        cases = [
            (COUPLED, x0[:2], "points: 2 coupled points given"),
            (COUPLED, np.where(np.eye(3, dtype=bool), float("nan"), x0), "points[0].position.x"),
            (BODY, x0, "joints: no coupled support"),
        ]
        static = cablesim.scene_to_dict(cablesim.load_scene(COUPLED))
        static["solver"]["analysis"] = "STATIC"
        del static["solver"]["initial_state"]
        cases.append((static, x0, "solver.analysis"))
        broken = cablesim.scene_to_dict(cablesim.load_scene(COUPLED))
        broken["cables"][1]["length"] = -1
        cases.append((broken, x0, "cables[1].length"))
        for scene, points, start in cases:
            with self.assertRaises(cablesim.Error) as raised:
                cablesim.couple(self.address, scene, points)
            self.assertEqual(raised.exception.code, "INVALID_ARGUMENT")
            self.assertTrue(raised.exception.details.startswith(start), raised.exception.details)
        # The slot is free again: a session opens.
        with cablesim.couple(self.address, COUPLED, x0) as session:
            self.assertEqual(session.time, 0)

    def test_a_session_is_a_counted_stream(self):
        x0 = self.start()
        with cablesim.couple(self.address, COUPLED, x0):
            with self.assertRaises(cablesim.Error) as raised:
                cablesim.couple(self.address, COUPLED, x0)
            self.assertEqual(raised.exception.code, "RESOURCE_EXHAUSTED")
            self.assertIn("max_streams_per_peer", raised.exception.details)
        with cablesim.couple(self.address, COUPLED, x0) as session:  # freed by the close
            session.step(0.05, x0)

    def test_token_and_stall_timeout(self):
        """A server with tokens and a short stall timeout."""
        with tempfile.TemporaryDirectory() as tmp:
            token = "tok-couple-0123456789"
            with open(os.path.join(tmp, "tokens"), "w") as f:
                f.write(token + " host\n")
            os.chmod(os.path.join(tmp, "tokens"), 0o600)
            os.mkdir(os.path.join(tmp, "data"))
            server, port = start_server(os.path.join(tmp, "data"),
                                        "--token-file=" + os.path.join(tmp, "tokens"),
                                        "--stall-timeout-s=1")
            try:
                address = "127.0.0.1:%d" % port
                x0 = self.start()
                with self.assertRaises(cablesim.Error) as raised:
                    cablesim.couple(address, COUPLED, x0)
                self.assertEqual(raised.exception.code, "UNAUTHENTICATED")
                with cablesim.couple(address, COUPLED, x0, token=token) as session:
                    session.step(0.05, x0)
                    # A host that sends nothing for the stall timeout is cut off.
                    time.sleep(3)
                    with self.assertRaises(cablesim.Error) as raised:
                        session.step(0.05, x0)
                    self.assertEqual(raised.exception.code, "CANCELLED")
            finally:
                server.terminate()
                server.wait(timeout=30)


if __name__ == "__main__":
    unittest.main()
