/* The coupled floater through libcablesim_couple (C, no C++).
 *
 * A floater (point mass m, buoyancy of a vertical cylinder rho g A s(z),
 * linear damping c, a harmonic external force in x and z) is integrated
 * here, by the host, with velocity Verlet (the damping implicit), and
 * moored by three lines in cablesim through CableSim_Init / CableSim_Step
 * (the forces Step returns: their mean over the coupling step). The
 * reference is the same floater modelled as a cablesim body in one scene
 * (tests/data/couple_floater_body.json, run by the cablesim CLI before this
 * test: argv[2] is its CSV; its step, 2.5 ms, is converged: the run at
 * 0.625 ms differs by 1e-5 m). The coupled motion must agree with it to the
 * coupling scheme's order as the coupling step shrinks: the largest error
 * in the plane of the forcing (x, z) over the frames (every 0.2 s for 5 s)
 * at coupling steps 0.05, 0.025, 0.0125 and 0.00625 s, the observed order
 * of each halving printed. The scheme is explicit (the lines see the
 * host's position at the step's end, reached linearly; the host uses the
 * lines' mean force over the step as the force at its end): first order.
 * Measured: 4.3e-3, 1.8e-3, 7.7e-4, 2.9e-4 m (orders 1.3, 1.2, 1.4). Each
 * halving must divide the error by at least 2^0.8 (0.8: a margin under the
 * first order for the pre-asymptotic range), and the finest error must be
 * below 1 % of the largest excursion of the reference. (Later than about
 * 6 s this symmetric motion loses its symmetry about the x-z plane: y grows
 * from rounding, differently in the two models, a bifurcation that no
 * coupling step follows; hence 5 s. The lines' end forces instead of the
 * means do not converge: 5e-2 m at every step, the impulse that the lines'
 * mass next to the fairlead takes at each step's start left out.)
 * Energy at the fairleads (CableSim_GetHostWork, CableSim_GetEnergy): the
 * work the host does on the lines over the 5 s, W = -sum over the steps of
 * the mean forces . the points' displacements, must equal the lines'
 * energy change plus what their damping and drag dissipated, up to the
 * quadrature: inside a coupling step the points' velocity v is constant,
 * so W is exactly the rectangle rule on the sub-steps' end forces
 * (sum h F_end . v), while the engine's energy identity books the
 * supports' work by the trapezoidal rule (sum h (F_before + F_end) / 2 .
 * v); within a step the difference telescopes to h / 2 v . (F_end of the
 * step - F_end of the step before), so |residual| <= sum over the steps
 * of h / 2 |v . dF| (h the sub-step; plus the integrator's own energy
 * error, measured below it). Measured over 5 s (W about -2.2 kJ, the
 * lines' energy change -7.0 kJ, dissipated 4.8 kJ): residual 18.6, 3.1,
 * 0.003 and -0.15 J at coupling steps 0.05, 0.025, 0.0125 and
 * 0.00625 s, bounds 90, 4.4, 3.2 and 2.5 J (the bound scales with the
 * sub-step, the residual falls faster: 6x for the first halving, then to
 * the integrator's level). The bound must also be below 2 % of the energy
 * exchanged (|change| + dissipated), so that the check says something; a
 * host work of the wrong sign would leave a residual of 4 kJ.
 * Bad input: each named argument gets CABLESIM_INVALID_ARGUMENT with a
 * message naming it, and the system stays usable.
 *
 * usage: couple_floater_test COUPLED_SCENE REFERENCE_CSV [COUPLING_STEP...] */

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "couple/cablesim_couple.h"
#include "tests/c_expect.h"

#define MAX_FRAMES 1000
/* The frames compared: up to 5 s (see main). */
static const double kCompareUntil = 5.0;
static const double kMass = 20000.0, kDamping = 20000.0, kRho = 1025.0, kG = 9.81;
static const double kDiameter = 4.0, kHeight = 4.0;


/* The reference: t, x, y, z of probe "floater" per frame. */
static int frames = 0;
static double ref_t[MAX_FRAMES], ref_x[MAX_FRAMES][3];

static int ReadReference(const char* path) {
  FILE* f = fopen(path, "r");
  if (!f) return 0;
  static char line[1 << 16];
  if (!fgets(line, sizeof line, f)) return 0;
  int col_t = -1, col_x = -1, k = 0;
  for (char* tok = strtok(line, ",\n"); tok; tok = strtok(NULL, ",\n"), ++k) {
    if (strcmp(tok, "t") == 0) col_t = k;
    if (strcmp(tok, "floater.x") == 0) col_x = k;
  }
  if (col_t < 0 || col_x < 0) return 0;
  while (frames < MAX_FRAMES && fgets(line, sizeof line, f)) {
    k = 0;
    for (char* tok = strtok(line, ",\n"); tok; tok = strtok(NULL, ",\n"), ++k) {
      if (k == col_t) ref_t[frames] = atof(tok);
      if (k >= col_x && k < col_x + 3) ref_x[frames][k - col_x] = atof(tok);
    }
    ++frames;
  }
  fclose(f);
  return frames > 1;
}

/* Buoyancy, gravity and the external force on the floater (not the lines',
 * not the damping) at position x and time t. */
static void HostForce(const double* x, double t, double* out) {
  const double area = M_PI * kDiameter * kDiameter / 4;
  double s = kHeight / 2 - x[2];
  if (s < 0) s = 0;
  if (s > kHeight) s = kHeight;
  out[0] = 20000.0 * sin(2 * M_PI * 0.1 * t);
  out[1] = 0;
  out[2] = kRho * kG * area * s - kMass * kG + 20000.0 * sin(2 * M_PI * 0.15 * t);
}

/* The energy balance at the fairleads of the last Coupled run [J]: the
 * host's work on the lines, the lines' energy change, their dissipation. */
static double balance_work, balance_energy, balance_dissipated, balance_bound;
static const double kSceneStep = 0.0025; /* the scene's solver.step */

/* Runs the coupled floater at coupling step dt; returns the largest
 * distance from the reference over the frames (negative on failure). */
static double Coupled(const char* scene, double dt) {
  CableSimSystem sys = CableSim_Create(scene);
  if (!sys) {
    fprintf(stderr, "CableSim_Create: %s\n", CableSim_ErrorMessage());
    return -1;
  }
  unsigned int ndof = 0;
  if (CableSim_NCoupledDOF(sys, &ndof) != CABLESIM_OK || ndof != 9) {
    fprintf(stderr, "NCoupledDOF %u: %s\n", ndof, CableSim_ErrorMessage());
    return -1;
  }
  double x[3], v[3] = {0, 0, 0}, X[9], XD[9], F[9];
  for (int d = 0; d < 3; ++d) x[d] = ref_x[0][d];
  for (int p = 0; p < 3; ++p)
    for (int d = 0; d < 3; ++d) X[3 * p + d] = x[d], XD[3 * p + d] = 0;
  if (CableSim_Init(sys, X, XD) != CABLESIM_OK) {
    fprintf(stderr, "CableSim_Init: %s\n", CableSim_ErrorMessage());
    return -1;
  }
  double energy0 = 0, dissipated0 = 0;
  CableSim_GetEnergy(sys, &energy0, &dissipated0);
  /* The lines' force at t = 0 (their static equilibrium with the floater
   * where the reference's statics put it). */
  double host[3], fm[3];
  if (CableSim_GetForces(sys, F) != CABLESIM_OK) return -1;
  for (int d = 0; d < 3; ++d) fm[d] = F[d] + F[3 + d] + F[6 + d];
  if (getenv("COUPLE_DEBUG")) {
    HostForce(x, 0, host);
    fprintf(stderr, "t=0 balance: %g %g %g (lines %g %g %g)\n", fm[0] + host[0], fm[1] + host[1],
            fm[2] + host[2], fm[0], fm[1], fm[2]);
  }
  double t = 0, err = 0, end_before[9];
  CableSim_GetForces(sys, end_before);
  balance_bound = 0;
  int next = 1;
  const long steps = lround(ref_t[frames - 1] / dt);
  for (long n = 0; n < steps; ++n) {
    double a[3], vh[3];
    HostForce(x, t, host);
    for (int d = 0; d < 3; ++d) {
      a[d] = (host[d] + fm[d] - kDamping * v[d]) / kMass;
      vh[d] = v[d] + 0.5 * dt * a[d];
      x[d] += dt * vh[d];
    }
    for (int p = 0; p < 3; ++p)
      for (int d = 0; d < 3; ++d) X[3 * p + d] = x[d], XD[3 * p + d] = vh[d];
    double step = dt;
    if (CableSim_Step(sys, X, XD, F, &t, &step) != CABLESIM_OK) {
      fprintf(stderr, "CableSim_Step at t = %g: %s\n", t, CableSim_ErrorMessage());
      CableSim_Close(sys);
      return -1;
    }
    {
      /* The balance's quadrature bound for this step: h / 2 |v . (F_end -
       * F_end before)| (see main). */
      double end[9], dot = 0;
      CableSim_GetForces(sys, end);
      for (int k = 0; k < 9; ++k) dot += vh[k % 3] * (end[k] - end_before[k]), end_before[k] = end[k];
      const double h = dt / ceil(dt / kSceneStep - 1e-9);
      balance_bound += 0.5 * h * fabs(dot);
    }
    if (getenv("COUPLE_END_FORCES")) CableSim_GetForces(sys, F); /* for measurements */
    HostForce(x, t, host);
    for (int d = 0; d < 3; ++d) {
      fm[d] = F[d] + F[3 + d] + F[6 + d];
      v[d] = (vh[d] + 0.5 * dt * (host[d] + fm[d]) / kMass) / (1 + 0.5 * dt * kDamping / kMass);
    }
    while (next < frames && fabs(ref_t[next] - t) <= 1e-9 && ref_t[next] <= kCompareUntil) {
      const double e = sqrt(pow(x[0] - ref_x[next][0], 2) + pow(x[2] - ref_x[next][2], 2));
      if (e > err) err = e;
      if (getenv("COUPLE_DEBUG") && next % 5 == 0)
        fprintf(stderr, "dt %g t %g err %g  dx %g %g %g\n", dt, t, e, x[0] - ref_x[next][0],
                x[1] - ref_x[next][1], x[2] - ref_x[next][2]);
      ++next;
    }
  }
  double energy = 0;
  CableSim_GetHostWork(sys, &balance_work);
  CableSim_GetEnergy(sys, &energy, &balance_dissipated);
  balance_energy = energy - energy0;
  CableSim_Close(sys);
  return ref_t[next - 1] + 1e-9 >= kCompareUntil ? err : -1;
}

static void BadInput(const char* scene) {
  CableSimSystem sys = CableSim_Create(scene);
  EXPECT(sys != NULL, "create: %s", CableSim_ErrorMessage());
  if (!sys) return;
  double X[9], XD[9] = {0}, F[9], t = 0, dt = 0.1;
  for (int p = 0; p < 3; ++p)
    for (int d = 0; d < 3; ++d) X[3 * p + d] = ref_x[0][d];
  EXPECT(CableSim_Step(sys, X, XD, F, &t, &dt) == CABLESIM_WRONG_STATE, "step before init");
  EXPECT(CableSim_Init(sys, X, XD) == CABLESIM_OK, "init: %s", CableSim_ErrorMessage());
  X[4] = NAN;
  EXPECT(CableSim_Step(sys, X, XD, F, &t, &dt) == CABLESIM_INVALID_ARGUMENT &&
             strstr(CableSim_ErrorMessage(), "x[1].y") != NULL,
         "non-finite x: %s", CableSim_ErrorMessage());
  X[4] = ref_x[0][1];
  XD[8] = INFINITY;
  EXPECT(CableSim_Step(sys, X, XD, F, &t, &dt) == CABLESIM_INVALID_ARGUMENT &&
             strstr(CableSim_ErrorMessage(), "xd[2].z") != NULL,
         "non-finite xd: %s", CableSim_ErrorMessage());
  XD[8] = 0;
  double back = -0.1;
  EXPECT(CableSim_Step(sys, X, XD, F, &t, &back) == CABLESIM_INVALID_ARGUMENT &&
             strstr(CableSim_ErrorMessage(), "dt:") != NULL,
         "negative dt: %s", CableSim_ErrorMessage());
  double early = -1;
  EXPECT(CableSim_Step(sys, X, XD, F, &early, &dt) == CABLESIM_INVALID_ARGUMENT &&
             strstr(CableSim_ErrorMessage(), "t:") != NULL,
         "time backwards: %s", CableSim_ErrorMessage());
  X[0] += 100;
  EXPECT(CableSim_Step(sys, X, XD, F, &t, &dt) == CABLESIM_INVALID_ARGUMENT &&
             strstr(CableSim_ErrorMessage(), "x[0]") != NULL,
         "jump: %s", CableSim_ErrorMessage());
  X[0] -= 100;
  EXPECT(CableSim_Step(sys, NULL, XD, F, &t, &dt) == CABLESIM_INVALID_ARGUMENT &&
             strstr(CableSim_ErrorMessage(), "x: null") != NULL,
         "null x: %s", CableSim_ErrorMessage());
  double pos[3], tension;
  EXPECT(CableSim_GetLineNodePos(sys, 3, 0, pos) == CABLESIM_INVALID_ARGUMENT &&
             strstr(CableSim_ErrorMessage(), "line:") != NULL,
         "line 3: %s", CableSim_ErrorMessage());
  /* Still usable: a step succeeds, and the lines' nodes and tensions read. */
  EXPECT(CableSim_Step(sys, X, XD, F, &t, &dt) == CABLESIM_OK && fabs(t - 0.1) < 1e-12,
         "step after bad input: %s", CableSim_ErrorMessage());
  unsigned int lines = 0, nodes = 0;
  EXPECT(CableSim_GetNumberLines(sys, &lines) == CABLESIM_OK && lines == 3, "lines");
  EXPECT(CableSim_GetLineNumberNodes(sys, 0, &nodes) == CABLESIM_OK && nodes == 11, "nodes %u",
         nodes);
  EXPECT(CableSim_GetLineNodePos(sys, 0, nodes - 1, pos) == CABLESIM_OK &&
             fabs(pos[2] - X[2]) < 1e-6,
         "fairlead node z %g against %g", pos[2], X[2]);
  EXPECT(CableSim_GetLineTension(sys, 0, nodes - 1, &tension) == CABLESIM_OK && tension > 1e4 &&
             tension < 1e5,
         "fairlead tension %g (the lines hold about a third of 58 kN up each)", tension);
  EXPECT(CableSim_GetLineTension(sys, 0, nodes, &tension) == CABLESIM_INVALID_ARGUMENT &&
             strstr(CableSim_ErrorMessage(), "node:") != NULL,
         "node past the end: %s", CableSim_ErrorMessage());
  EXPECT(CableSim_Create("/nonexistent/scene.json") == NULL &&
             strstr(CableSim_ErrorMessage(), "/nonexistent/scene.json") != NULL,
         "missing file: %s", CableSim_ErrorMessage());
  CableSim_Close(sys);
}

int main(int argc, char** argv) {
  if (argc < 3 || !ReadReference(argv[2])) {
    fprintf(stderr, "usage: %s COUPLED_SCENE REFERENCE_CSV (readable, with floater.x)\n", argv[0]);
    return 2;
  }
  double excursion = 0;
  for (int k = 0; k < frames; ++k) {
    const double e = sqrt(pow(ref_x[k][0] - ref_x[0][0], 2) + pow(ref_x[k][1] - ref_x[0][1], 2) +
                          pow(ref_x[k][2] - ref_x[0][2], 2));
    if (e > excursion) excursion = e;
  }
  BadInput(argv[1]);
  double steps[8] = {0.05, 0.025, 0.0125, 0.00625};
  int count = 4;
  if (argc > 3) { /* other coupling steps, halving, for measurements */
    count = 0;
    for (int i = 3; i < argc && count < 8; ++i) steps[count++] = atof(argv[i]);
  }
  double err[8], residual[8];
  for (int i = 0; i < count; ++i) {
    err[i] = Coupled(argv[1], steps[i]);
    printf("coupling step %.3f s: largest distance from the reference %.4e m\n", steps[i], err[i]);
    EXPECT(err[i] >= 0, "coupled run at %g s failed", steps[i]);
    residual[i] = balance_work - balance_energy - balance_dissipated;
    printf("  energy at the fairleads over 5 s: host work %.6g J = lines' energy change %.6g J "
           "+ dissipated %.6g J + residual %.4g J (quadrature bound %.4g J)\n",
           balance_work, balance_energy, balance_dissipated, residual[i], balance_bound);
    EXPECT(fabs(residual[i]) <= balance_bound,
           "energy balance at %g s: residual %g J beyond the quadrature bound %g J", steps[i],
           residual[i], balance_bound);
    EXPECT(balance_bound <= 0.02 * (fabs(balance_energy) + balance_dissipated),
           "energy balance at %g s: the bound %g J says nothing", steps[i], balance_bound);
  }
  for (int i = 1; i < count; ++i) {
    const double order = log(err[i - 1] / err[i]) / log(2.0);
    printf("observed order %.3f -> %.3f s: %.2f\n", steps[i - 1], steps[i], order);
    EXPECT(order >= 0.8, "order %.2f from %g to %g s", order, steps[i - 1], steps[i]);
  }
  printf("reference excursion %.4f m\n", excursion);
  EXPECT(err[count - 1] < 0.01 * excursion, "finest error %g against excursion %g", err[count - 1],
         excursion);
  printf("%d passed, %d failed\n", failures == 0 ? 1 : 0, failures == 0 ? 0 : 1);
  return failures == 0 ? 0 : 1;
}
