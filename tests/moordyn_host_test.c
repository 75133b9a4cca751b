/* A host loop written against MoorDyn v2's C function names, built with
 * cablesim's couple/ on the include path and linked to libcablesim_couple:
 * the switch the coupling issue promises (the include path and the link
 * line, nothing else). The calls and their order are those of MoorDyn's
 * documented C example: create from a deck, read the fairlead points'
 * positions by their IDs, initialise, step with the fairleads moving, read
 * every line's node positions and tensions.
 *
 * The deck (tests/data/moordyn_three_lines.dat): three 420 m chains at 120
 * degrees from anchors 400 m out at 100 m depth to fairleads (Vessel points
 * 4, 5, 6) 5 m from the centre. Checked:
 *  - 9 coupled degrees of freedom, the fairleads where the deck puts them;
 *  - at rest after Init (one step with the fairleads still), each
 *    fairlead's force has the size of its line's end tension
 *    (MoorDyn_GetLineFairTen) to 1e-6 (statics: the end tension is the
 *    support's force to the Newton tolerance), the three are alike to 1e-6
 *    (the deck is symmetric) and their horizontal sum vanishes to 1e-6 of
 *    one; each node tension vector has the size of its node's tension;
 *  - moved 2 m along +x (0.5 m/s for 4 s), the net horizontal force
 *    points back (-x): the mooring restores;
 *  - bad arguments: a line or point that does not exist gives NULL, a null
 *    output pointer MOORDYN_INVALID_INPUT, each with a message naming it.
 *
 * usage: moordyn_host_test DECK */

#include <math.h>
#include <stdio.h>
#include <string.h>

#include <moordyn/MoorDyn2.h>

#include "couple/cablesim_couple.h" /* CableSim_ErrorMessage only */
#include "tests/c_expect.h"


static double Norm(const double* v) { return sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

int main(int argc, char** argv) {
  if (argc != 2) {
    fprintf(stderr, "usage: %s DECK\n", argv[0]);
    return 2;
  }
  MoorDyn system = MoorDyn_Create(argv[1]);
  if (!system) {
    fprintf(stderr, "MoorDyn_Create: %s\n", CableSim_ErrorMessage());
    return 1;
  }
  unsigned int dof = 0;
  EXPECT(MoorDyn_NCoupledDOF(system, &dof) == MOORDYN_SUCCESS && dof == 9, "dof %u", dof);

  double x[9], xd[9], f[9];
  memset(xd, 0, sizeof(xd));
  for (unsigned int i = 0; i < 3; i++) {
    MoorDynPoint point = MoorDyn_GetPoint(system, i + 4);
    EXPECT(point != NULL, "point %u: %s", i + 4, CableSim_ErrorMessage());
    if (!point || MoorDyn_GetPointPos(point, x + 3 * i) != MOORDYN_SUCCESS) {
      MoorDyn_Close(system);
      return 1;
    }
    const double angle = 2 * M_PI / 3 * i;
    EXPECT(fabs(x[3 * i] - 5 * cos(angle)) < 1e-3 && fabs(x[3 * i + 1] - 5 * sin(angle)) < 1e-3 &&
               x[3 * i + 2] == -5,
           "fairlead %u at (%g, %g, %g)", i + 4, x[3 * i], x[3 * i + 1], x[3 * i + 2]);
  }
  int err = MoorDyn_Init(system, x, xd);
  EXPECT(err == MOORDYN_SUCCESS, "MoorDyn_Init: %d %s", err, CableSim_ErrorMessage());
  if (err != MOORDYN_SUCCESS) {
    MoorDyn_Close(system);
    return 1;
  }

  /* At rest. */
  double t = 0.0, dt = 0.1;
  err = MoorDyn_Step(system, x, xd, f, &t, &dt);
  EXPECT(err == MOORDYN_SUCCESS, "MoorDyn_Step at rest: %d %s", err, CableSim_ErrorMessage());
  double sum_x = 0, sum_y = 0, first = Norm(f);
  for (unsigned int i = 0; i < 3; i++) {
    MoorDynLine line = MoorDyn_GetLine(system, i + 1);
    double fair = 0;
    EXPECT(line && MoorDyn_GetLineFairTen(line, &fair) == MOORDYN_SUCCESS, "line %u", i + 1);
    const double force = Norm(f + 3 * i);
    printf("line %u: fairlead force %.6e N, end tension %.6e N\n", i + 1, force, fair);
    EXPECT(fabs(force - fair) <= 1e-6 * fair, "line %u: force %.9g N, FairTen %.9g N", i + 1,
           force, fair);
    EXPECT(fabs(force - first) <= 1e-6 * first, "line %u: %.9g N against line 1's %.9g N", i + 1,
           force, first);
    sum_x += f[3 * i];
    sum_y += f[3 * i + 1];
  }
  EXPECT(hypot(sum_x, sum_y) <= 1e-6 * first, "horizontal sum (%g, %g) N", sum_x, sum_y);

  /* Every line's nodes, as MoorDyn's example prints them. */
  unsigned int n_lines = 0;
  EXPECT(MoorDyn_GetNumberLines(system, &n_lines) == MOORDYN_SUCCESS && n_lines == 3,
         "lines %u", n_lines);
  for (unsigned int i = 0; i < n_lines; i++) {
    MoorDynLine line = MoorDyn_GetLine(system, i + 1);
    unsigned int n_nodes = 0;
    EXPECT(MoorDyn_GetLineNumberNodes(line, &n_nodes) == MOORDYN_SUCCESS && n_nodes == 21,
           "line %u: %u nodes", i + 1, n_nodes);
    for (unsigned int j = 0; j < n_nodes; j++) {
      double pos[3], ten[3], size = 0;
      EXPECT(MoorDyn_GetLineNodePos(line, j, pos) == MOORDYN_SUCCESS, "node %u pos", j);
      EXPECT(MoorDyn_GetLineNodeTen(line, j, ten) == MOORDYN_SUCCESS, "node %u ten", j);
      if (j + 1 == n_nodes) {
        MoorDyn_GetLineFairTen(line, &size);
        EXPECT(fabs(Norm(ten) - fabs(size)) <= 1e-9 * fabs(size), "node %u: |ten| %g, %g", j,
               Norm(ten), size);
      }
      EXPECT(pos[2] >= -100.01 && pos[2] <= -4.99, "line %u node %u at z = %g", i + 1, j, pos[2]);
    }
  }

  /* Moved 2 m along +x. */
  for (unsigned int i = 0; i < 3; i++) xd[3 * i] = 0.5;
  for (int k = 0; k < 40; k++) {
    for (unsigned int i = 0; i < 3; i++) x[3 * i] += 0.5 * dt;
    err = MoorDyn_Step(system, x, xd, f, &t, &dt);
    if (err != MOORDYN_SUCCESS) break;
  }
  EXPECT(err == MOORDYN_SUCCESS, "MoorDyn_Step moving: %d %s", err, CableSim_ErrorMessage());
  EXPECT(fabs(t - 4.1) < 1e-9, "t = %.12g s", t);
  sum_x = f[0] + f[3] + f[6];
  printf("moved 2 m along +x: net force x %.6e N\n", sum_x);
  EXPECT(sum_x < -1e3, "net x force %g N does not restore", sum_x);

  /* Bad arguments. */
  EXPECT(MoorDyn_GetLine(system, 4) == NULL && strstr(CableSim_ErrorMessage(), "no line 4"),
         "line 4: %s", CableSim_ErrorMessage());
  EXPECT(MoorDyn_GetPoint(system, 7) == NULL && strstr(CableSim_ErrorMessage(), "no point 7"),
         "point 7: %s", CableSim_ErrorMessage());
  EXPECT(MoorDyn_GetLineFairTen(MoorDyn_GetLine(system, 1), NULL) == MOORDYN_INVALID_INPUT &&
             strstr(CableSim_ErrorMessage(), "t: null"),
         "t null: %s", CableSim_ErrorMessage());
  EXPECT(MoorDyn_Step(system, x, xd, NULL, &t, &dt) == MOORDYN_INVALID_INPUT &&
             strstr(CableSim_ErrorMessage(), "f: null"),
         "f null: %s", CableSim_ErrorMessage());

  MoorDyn_Close(system);
  if (failures) {
    fprintf(stderr, "%d failures\n", failures);
    return 1;
  }
  printf("OK\n");
  return 0;
}
