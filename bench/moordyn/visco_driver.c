/* Drives MoorDyn-C's one-segment viscoelastic line for bench/moordyn/compare_visco.py: the
 * fairlead (point 2) moves along x as x(t) = x0 + a (1 - cos(2 pi t / period)), and the
 * fairlead's line force is written every `every` steps of `dt` to OUT as "t,tension" rows.
 *
 *   visco_driver DECK OUT a period dt steps every
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "MoorDyn2.h"

int main(int argc, char** argv) {
  if (argc != 8) {
    fprintf(stderr, "usage: %s DECK OUT a period dt steps every\n", argv[0]);
    return 2;
  }
  const double a = atof(argv[3]), w = 2 * M_PI / atof(argv[4]), dt = atof(argv[5]);
  const int steps = atoi(argv[6]), every = atoi(argv[7]);
  MoorDyn system = MoorDyn_Create(argv[1]);
  if (!system) return 1;
  MoorDynPoint fairlead = MoorDyn_GetPoint(system, 2);
  double r[3], dr[3] = {0, 0, 0}, f[3];
  if (MoorDyn_GetPointPos(fairlead, r) != MOORDYN_SUCCESS) return 1;
  const double x0 = r[0];
  if (MoorDyn_Init_NoIC(system, r, dr) != MOORDYN_SUCCESS) return 1;
  FILE* out = fopen(argv[2], "w");
  if (!out) return 1;
  fprintf(out, "t,tension\n");
  double t = 0;
  for (int i = 1; i <= steps; ++i) {
    /* The position at the step's start and the velocity that reaches the next one. */
    r[0] = x0 + a * (1 - cos(w * t));
    dr[0] = (x0 + a * (1 - cos(w * i * dt)) - r[0]) / dt;
    double h = dt;
    if (MoorDyn_Step(system, r, dr, f, &t, &h) != MOORDYN_SUCCESS) return 1;
    if (i % every == 0) fprintf(out, "%.6f,%.12g\n", t, -f[0]);
  }
  fclose(out);
  MoorDyn_Close(system);
  return 0;
}
