/* A coupled body through libcablesim_couple (issue 33): its force and
 * moment against an independent route, and its bad inputs.
 *
 * tests/data/couple_body_coupled.json: a body of the scene marked coupled,
 * three lines pinned to it at 10 m from its centre (the floater's lines
 * moved out by 10 m). tests/data/couple_body_points.json: the same lines
 * with their fairleads as coupled supports instead (no body). The host
 * moves the body: centre x(t) = (0.5 t, 0, 0) m, orientation turning at
 * 0.1 rad/s about the tilted axis a = (0, 0.5, 1) / |.| (yaw and pitch)
 * from an initial turn of 0.2 rad; the points' host puts each fairlead at
 * x + R p_k (p_k its body point) with velocity v + omega x R p_k.
 *
 * (a) At Init (statics at the turned pose, at rest) the body's force is
 *     the sum of the points' forces and its moment the sum of r_k x F_k,
 *     r_k = R p_k: both sessions solve the same equilibrium to Newton's
 *     tolerance, so they agree to 1e-8 of |F| (and of |F| r for the
 *     moment; measured 1e-9). Then the host turns the body at a constant
 *     rate w (and surges it) for 20 coupling steps of 0.05 s. Inside a
 *     step the body's points move on arcs (slerp) and the points' on
 *     chords; the forces compared are those at each step's end (the means
 *     of r x F over a step are not r x the mean F): they part by at most r (w dt)^2 / 8 and differ in
 *     acceleration by w^2 r, so the two routes' mean forces differ at
 *     second order in w, not more. The test measures the largest
 *     difference e(w) over the steps (of |F|, and of |F| r for the
 *     moment) at w = 0.1 and 0.05 rad/s and checks that it is second
 *     order, e(w) / e(w / 2) within [3, 5.5] (measured 4.3; a
 *     first-order discrepancy gives 2), and of the size of the line mass
 *     next to the fairleads (one element each, 3 x 353 kg) times w^2 r
 *     over |F|, 1.8e-3 at w = 0.1 rad/s: below 5e-3 (measured 2.2e-3). A
 *     wrong sign in the moment moves it by 2 |M| / (|F| r) = 0.1, the
 *     transposed rotation moves the fairleads by 2 w r = 4 m.
 * MoorDyn's names: the same body through MoorDyn_Create / Init / Step with
 * its 6 coupled degrees of freedom (x, y, z, roll, pitch, yaw; MoorDyn v2's
 * R = Rx(roll) Ry(pitch) Rz(yaw)) gives the force and moment of the
 * cablesim-named system driven by the quaternion qx qy qz multiplied out
 * here, to rounding (1e-9 of |F|: the same equations, so only a wrong
 * convention or layout can part them; the order Rz Ry Rx instead moves the
 * fairleads by centimetres, the moment by 1e-3 and more).
 * (c) Bad inputs each return CABLESIM_INVALID_ARGUMENT naming the argument
 *     and leave the system usable: a body that does not exist, a quaternion
 *     that is not unit, a non-finite quaternion, a non-finite angular
 *     velocity, a jump longer than an element. */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "couple/cablesim_couple.h"
#include "moordyn/MoorDyn2.h"
#include "tests/c_expect.h"

static const double kAxis[3] = {0, 0.4472135954999579, 0.8944271909999159};
static const double kTurn0 = 0.2, kSurge = 0.5;

/* q (w, x, y, z) for a turn of `angle` about kAxis, and its matrix. */
static void Quaternion(double angle, double q[4]) {
  q[0] = cos(angle / 2);
  for (int d = 0; d < 3; ++d) q[1 + d] = sin(angle / 2) * kAxis[d];
}
static void Rotate(const double q[4], const double p[3], double out[3]) {
  const double w = q[0], x = q[1], y = q[2], z = q[3];
  const double r[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                          {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                          {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
  for (int i = 0; i < 3; ++i) out[i] = r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2];
}
static void Cross(const double a[3], const double b[3], double c[3]) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
static double Norm(const double a[3]) { return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

/* The body points of the fairleads (the body's scene axes are the world's). */
static double points[3][3];

/* The host's pose at time t, turning at `rate` about kAxis from kTurn0
 * and surging (at rest: rate 0): body kinematics and the fairleads'. */
static void Pose(double t, double rate, double pos[3], double q[4], double vel[3],
                 double omega[3], double x[9], double xd[9]) {
  const double surge = rate > 0 ? kSurge : 0;
  pos[0] = surge * t, pos[1] = 0, pos[2] = 0;
  vel[0] = surge, vel[1] = 0, vel[2] = 0;
  Quaternion(kTurn0 + rate * t, q);
  for (int d = 0; d < 3; ++d) omega[d] = rate * kAxis[d];
  for (int k = 0; k < 3; ++k) {
    double r[3], w[3];
    Rotate(q, points[k], r);
    Cross(omega, r, w);
    for (int d = 0; d < 3; ++d) x[3 * k + d] = pos[d] + r[d], xd[3 * k + d] = vel[d] + w[d];
  }
}

/* The points' resultant force and moment about pos. */
static void Resultant(const double x[9], const double f[9], const double pos[3], double force[3],
                      double moment[3]) {
  for (int d = 0; d < 3; ++d) force[d] = moment[d] = 0;
  for (int k = 0; k < 3; ++k) {
    double r[3], m[3];
    for (int d = 0; d < 3; ++d) r[d] = x[3 * k + d] - pos[d];
    Cross(r, f + 3 * k, m);
    for (int d = 0; d < 3; ++d) force[d] += f[3 * k + d], moment[d] += m[d];
  }
}

static double Diff(const double a[3], const double b[3]) {
  const double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
  return Norm(d);
}

static void Compare(const char* when, const double fb[3], const double mb[3], const double fp[3],
                    const double mp[3], double tol) {
  const double scale = Norm(fp);
  const double df = Diff(fb, fp) / scale, dm = Diff(mb, mp) / (scale * 10.0);
  printf("%s: |F| = %.6g N, |M| = %.6g N m; force off by %.3g, moment by %.3g (of |F|, |F| r)\n",
         when, Norm(fb), Norm(mb), df, dm);
  EXPECT(df <= tol, "%s: the body's force is %.3g of |F| off the points' sum", when, df);
  EXPECT(dm <= tol, "%s: the body's moment is %.3g of |F| r off the points' sum r x F", when, dm);
}

static int Expect(int rc, const char* needle, const char* what) {
  const char* message = CableSim_ErrorMessage();
  EXPECT(rc == CABLESIM_INVALID_ARGUMENT, "%s: code %d (%s)", what, rc, message);
  EXPECT(strstr(message, needle) != NULL, "%s: the message '%s' does not name '%s'", what, message,
        needle);
  printf("%s: %s\n", what, message);
  return rc;
}

/* Opens both systems with the body turned by kTurn0 at rest, compares
 * them at t = 0, runs 20 steps turning at `rate` [rad/s], returns the
 * largest difference (of |F|, |F| r). With `bad` also the bad inputs. */
static double Run(const char* body_file, const char* points_file, double rate, int bad) {
  CableSimSystem body = CableSim_Create(body_file);
  CableSimSystem pts = CableSim_Create(points_file);
  if (body == NULL || pts == NULL) {
    fprintf(stderr, "create: %s\n", CableSim_ErrorMessage());
    exit(1);
  }
  unsigned int nb = 0, ndof = 0, np = 0;
  CableSim_NCoupledBodies(body, &nb);
  CableSim_NCoupledDOF(body, &ndof);
  CableSim_NCoupledDOF(pts, &np);
  EXPECT(nb == 1 && ndof == 0 && np == 9, "coupled: %u bodies, %u and %u dof", nb, ndof, np);
  /* The fairleads' body points: where the points' scene starts them. */
  for (unsigned int line = 0; line < 3; ++line) {
    unsigned int nodes = 0;
    CableSim_GetLineNumberNodes(pts, line, &nodes);
    CableSim_GetLineNodePos(pts, line, nodes - 1, points[line]);
  }
  double scene_pos[3], scene_q[4];
  CableSim_GetBodyScenePose(body, 0, scene_pos, scene_q);
  EXPECT(Norm(scene_pos) < 1e-12 && fabs(scene_q[0] - 1) < 1e-12, "scene pose (%g %g %g) w %g",
         scene_pos[0], scene_pos[1], scene_pos[2], scene_q[0]);

  double pos[3], q[4], vel[3], omega[3], x[9], xd[9], f[9], fb[3], mb[3], fp[3], mp[3];
  Pose(0, 0, pos, q, vel, omega, x, xd);  /* at rest */
  if (CableSim_SetBodyKinematics(body, 0, pos, q, vel, omega) != CABLESIM_OK ||
      CableSim_Init(body, NULL, NULL) != CABLESIM_OK || CableSim_Init(pts, x, xd) != CABLESIM_OK) {
    fprintf(stderr, "init: %s\n", CableSim_ErrorMessage());
    exit(1);
  }
  CableSim_GetBodyForces(body, 0, fb, mb);
  CableSim_GetForces(pts, f);
  Resultant(x, f, pos, fp, mp);
  Compare("t = 0 (statics)", fb, mb, fp, mp, 1e-8);

  if (bad) {
    /* (c) Bad inputs, each leaving the system usable. */
    const double bad_norm[4] = {1.1, 0, 0, 0};
    const double bad_nan[4] = {1, 0, NAN, 0};
    const double bad_omega[3] = {0, INFINITY, 0};
    Expect(CableSim_SetBodyKinematics(body, 1, pos, q, vel, omega), "body: 1 is not",
           "a body that does not exist");
    Expect(CableSim_SetBodyKinematics(body, 0, pos, bad_norm, vel, omega), "q: must be a unit",
           "a quaternion not unit");
    Expect(CableSim_SetBodyKinematics(body, 0, pos, bad_nan, vel, omega), "q[2]", "a NaN in q");
    Expect(CableSim_SetBodyKinematics(body, 0, pos, q, vel, bad_omega), "omega[1]",
           "an infinite angular velocity");
    double far[3] = {pos[0] + 30, pos[1], pos[2]}, t = 0, dt = 0.05, f_body[3], m_body[3];
    CableSim_SetBodyKinematics(body, 0, far, q, vel, omega);
    Expect(CableSim_Step(body, NULL, NULL, NULL, &t, &dt), "bodies[0]", "a jump of 30 m");
    EXPECT(t == 0, "the refused step moved the time to %g", t);
    CableSim_GetBodyForces(body, 0, f_body, m_body);
    EXPECT(Diff(f_body, fb) == 0, "the refused step changed the forces");
    Expect(CableSim_GetBodyForces(body, 3, fb, mb), "body: 3 is not",
           "forces of a body that does not exist");
  }

  /* The same motion on both sides. */
  double t_body = 0, t_pts = 0, worst = 0;
  for (int n = 1; n <= 20; ++n) {
    double dt = 0.05, dt2 = 0.05;
    Pose(n * dt, rate, pos, q, vel, omega, x, xd);
    int rc = CableSim_SetBodyKinematics(body, 0, pos, q, vel, omega);
    if (rc == CABLESIM_OK) rc = CableSim_Step(body, NULL, NULL, NULL, &t_body, &dt);
    if (rc == CABLESIM_OK) rc = CableSim_Step(pts, x, xd, f, &t_pts, &dt2);
    if (rc != CABLESIM_OK) {
      fprintf(stderr, "step %d: %s\n", n, CableSim_ErrorMessage());
      exit(1);
    }
    /* At the step's end, where every r_k is known (the means of r x F
     * over a step are not the mean r x the mean F). */
    CableSim_GetBodyEndForces(body, 0, fb, mb);
    CableSim_GetForces(pts, f);
    Resultant(x, f, pos, fp, mp);
    const double scale = Norm(fp);
    const double e = fmax(Diff(fb, fp) / scale, Diff(mb, mp) / (10 * scale));
    if (e > worst) worst = e;
    if (getenv("COUPLE_BODY_VERBOSE")) printf("  step %d: %.3g %.3g\n", n, Diff(fb, fp) / scale, Diff(mb, mp) / (10 * scale));
  }
  printf("turning at %g rad/s: largest difference over 20 steps %.3g (of |F|, |F| r)\n", rate,
         worst);
  CableSim_Close(body);
  CableSim_Close(pts);
  return worst;
}

/* q = a * b (w, x, y, z). */
static void Multiply(const double a[4], const double b[4], double q[4]) {
  q[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
  q[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
  q[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
  q[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}

/* The body through MoorDyn's names against cablesim's, one step. */
static void MoorDynNames(const char* body_file) {
  const double angles[3] = {0.05, -0.08, 0.3}; /* roll, pitch, yaw [rad] */
  MoorDyn md = MoorDyn_Create(body_file);
  CableSimSystem cs = CableSim_Create(body_file);
  if (md == NULL || cs == NULL) {
    fprintf(stderr, "create: %s\n", CableSim_ErrorMessage());
    exit(1);
  }
  unsigned int n = 0;
  EXPECT(MoorDyn_NCoupledDOF(md, &n) == MOORDYN_SUCCESS && n == 6, "MoorDyn dof %u", n);
  double x[6] = {0.1, 0, 0, angles[0], angles[1], angles[2]}, xd[6] = {0}, f[6];
  double qx[4] = {cos(angles[0] / 2), sin(angles[0] / 2), 0, 0};
  double qy[4] = {cos(angles[1] / 2), 0, sin(angles[1] / 2), 0};
  double qz[4] = {cos(angles[2] / 2), 0, 0, sin(angles[2] / 2)};
  double qxy[4], q[4], zero[3] = {0, 0, 0}, fb[3], mb[3];
  Multiply(qx, qy, qxy);
  Multiply(qxy, qz, q);
  EXPECT(MoorDyn_Init(md, x, xd) == MOORDYN_SUCCESS, "MoorDyn_Init: %s", CableSim_ErrorMessage());
  EXPECT(CableSim_SetBodyKinematics(cs, 0, x, q, zero, zero) == CABLESIM_OK &&
             CableSim_Init(cs, NULL, NULL) == CABLESIM_OK,
         "CableSim_Init: %s", CableSim_ErrorMessage());
  double t = 0, dt = 0.05, t2 = 0, dt2 = 0.05;
  x[0] += 0.02;
  EXPECT(MoorDyn_Step(md, x, xd, f, &t, &dt) == MOORDYN_SUCCESS, "MoorDyn_Step: %s",
         CableSim_ErrorMessage());
  EXPECT(CableSim_SetBodyKinematics(cs, 0, x, q, zero, zero) == CABLESIM_OK &&
             CableSim_Step(cs, NULL, NULL, NULL, &t2, &dt2) == CABLESIM_OK,
         "CableSim_Step: %s", CableSim_ErrorMessage());
  CableSim_GetBodyForces(cs, 0, fb, mb);
  Compare("MoorDyn's names (roll, pitch, yaw)", f, f + 3, fb, mb, 1e-9);
  /* A bad angle is named through the 6 it came from. */
  x[4] = NAN;
  EXPECT(MoorDyn_Step(md, x, xd, f, &t, &dt) == MOORDYN_INVALID_INPUT &&
             strstr(CableSim_ErrorMessage(), "coupled body 0") != NULL,
         "MoorDyn_Step with a NaN pitch: %s", CableSim_ErrorMessage());
  MoorDyn_Close(md);
  CableSim_Close(cs);
}

int main(int argc, char** argv) {
  if (argc != 3) {
    fprintf(stderr, "usage: %s couple_body_coupled.json couple_body_points.json\n", argv[0]);
    return 2;
  }
  const double e1 = Run(argv[1], argv[2], 0.1, 1);
  const double e2 = Run(argv[1], argv[2], 0.05, 0);
  MoorDynNames(argv[1]);
  printf("ratio %.3f (second order: 4)\n", e1 / e2);
  EXPECT(e1 / e2 >= 3 && e1 / e2 <= 5.5, "the routes differ at order %.2f in w, not 2",
         log(e1 / e2) / log(2));
  EXPECT(e1 <= 5e-3, "the routes differ by %.3g of |F| at w = 0.1 rad/s", e1);
  if (failures) fprintf(stderr, "%d failure(s)\n", failures);
  return failures ? 1 : 0;
}
