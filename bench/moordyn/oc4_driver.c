/* MoorDyn-C driven through the fairlead motion of bench/scenes/oc4-three-lines.json, for
   bench/moordyn/compare_oc4.py (issue 34: cablesim against MoorDyn at equal accuracy).

     oc4_driver DECK OUT.csv COUPLING_DT

   The deck's points 4, 5 and 6 are coupled (the fairleads of lines 1, 2 and 3). They move
   together: surge x = r(t) 10 sin(2 pi t / 50) m and heave z = r(t) 2 sin(2 pi t / 10) m, r(t) a
   ramp from 0 to 1 over the first 50 s, as in the scene. MoorDyn is given their position and
   velocity every COUPLING_DT seconds (it moves a coupled point at that velocity through the
   interval: 2e-4 m off the scene's motion at 0.02 s), and its own step dtM is the deck's. The
   tension written is the size of the force the lines put on each coupled point (the force
   MoorDyn_Step returns), at t = 0 and every 0.1 s to 300 s: columns time,
   fairlead1.tension, fairlead2.tension, fairlead3.tension. Exit 1 if MoorDyn fails (an
   unstable dtM ends in its error). Uses MoorDyn's C API only (MoorDyn2.h). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include "MoorDyn2.h"

static const double x0[3][3] = {{20.434, 35.393, -14.0}, {-40.868, 0.0, -14.0}, {20.434, -35.393, -14.0}};

static void motion(double t, double* x, double* v) {
  const double w1 = 2 * M_PI * 0.02, w2 = 2 * M_PI * 0.1;
  const double r = t < 50 ? t / 50 : 1, dr = t < 50 ? 1.0 / 50 : 0;
  x[0] = 10 * r * sin(w1 * t); v[0] = 10 * (dr * sin(w1 * t) + r * w1 * cos(w1 * t));
  x[1] = 0; v[1] = 0;
  x[2] = 2 * r * sin(w2 * t); v[2] = 2 * (dr * sin(w2 * t) + r * w2 * cos(w2 * t));
}

int main(int argc, char** argv) {
  if (argc < 4) { fprintf(stderr, "oc4_driver DECK OUT.csv COUPLING_DT\n"); return 2; }
  const double dtc = atof(argv[3]), duration = 300, dt_out = 0.1;
  const long steps = lround(duration / dtc), per_out = lround(dt_out / dtc);
  if (per_out < 1 || fabs(per_out * dtc - dt_out) > 1e-12) {
    fprintf(stderr, "COUPLING_DT must divide 0.1 s\n");
    return 2;
  }
  MoorDyn sys = MoorDyn_Create(argv[1]);
  if (!sys) return 1;
  MoorDyn_SetVerbosity(sys, 0);
  unsigned int n = 0;
  MoorDyn_NCoupledDOF(sys, &n);
  if (n != 9) { fprintf(stderr, "coupled DOF %u\n", n); return 1; }
  double x[9], v[9], f[9], d[3], dv[3];
  motion(0, d, dv);
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) { x[3 * i + k] = x0[i][k] + d[k]; v[3 * i + k] = dv[k]; }
  if (MoorDyn_Init(sys, x, v) != MOORDYN_SUCCESS) return 1;
  FILE* out = fopen(argv[2], "w");
  fprintf(out, "time,fairlead1.tension,fairlead2.tension,fairlead3.tension\n");
  double t = 0;
  fprintf(out, "0");
  for (unsigned int i = 0; i < 3; ++i) {
    double g[3];
    MoorDyn_GetPointForce(MoorDyn_GetPoint(sys, 4 + i), g);
    fprintf(out, ",%.10g", sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]));
  }
  fprintf(out, "\n");
  for (long s = 0; s < steps; ++s) {
    motion(t, d, dv);
    for (int i = 0; i < 3; ++i)
      for (int k = 0; k < 3; ++k) { x[3 * i + k] = x0[i][k] + d[k]; v[3 * i + k] = dv[k]; }
    double dt = dtc;
    if (MoorDyn_Step(sys, x, v, f, &t, &dt) != MOORDYN_SUCCESS) return 1;
    t = (s + 1) * dtc;
    if ((s + 1) % per_out == 0) {
      fprintf(out, "%.10g", t);
      for (int i = 0; i < 3; ++i)
        fprintf(out, ",%.10g", sqrt(f[3 * i] * f[3 * i] + f[3 * i + 1] * f[3 * i + 1] + f[3 * i + 2] * f[3 * i + 2]));
      fprintf(out, "\n");
    }
  }
  fclose(out);
  MoorDyn_Close(sys);
  return 0;
}
