#ifndef CABLESIM_COUPLE_MOORDYN_MOORDYN2_H_
#define CABLESIM_COUPLE_MOORDYN_MOORDYN2_H_

/* cablesim behind the function names of MoorDyn v2's C interface, so that a
 * host program written for MoorDyn switches to cablesim by its include path
 * (-I<cablesim>/couple) and its link line (-lcablesim_couple) alone. Part
 * of libcablesim_couple; its own interface is couple/cablesim_couple.h.
 *
 * What is provided: the system (create from a MoorDyn v2 deck or a cablesim
 * scene, count the coupled degrees of freedom, initialise, step, close),
 * its lines (count, node count, node positions, node tension vectors, the
 * fairlead tension) and its points (count, the position of a point by its
 * deck ID). Nothing else of MoorDyn's interface is declared, so a host that
 * uses more fails to compile, naming the function, rather than at run time.
 *
 * Conventions, as a MoorDyn host expects them:
 *  - the coupled degrees of freedom are first 6 per coupled body (a cablesim
 *    scene's bodies with "coupled": true, in scene order; decks' coupled
 *    bodies are not read yet), then 3 per coupled point (the deck's
 *    Vessel or Coupled points; in a cablesim scene, joints to ground with
 *    "coupled": true, one point per distinct joint name), in increasing
 *    point ID (scene order for a cablesim scene); every line end held at a
 *    point moves with it and the point's force is their sum;
 *  - lines and points are numbered from 1 (MoorDyn_GetLine(sys, 1) is the
 *    deck's line 1; MoorDyn_GetPoint takes the deck's point ID);
 *  - a line's nodes run from end A (node 0) to end B, one per element end;
 *  - a coupled body's 6 are x, y, z of its reference point (its centre of
 *    mass) and its roll, pitch, yaw [rad], the orientation being
 *    R = Rx(roll) Ry(pitch) Rz(yaw) (MoorDyn v2's for coupled bodies; its
 *    columns are the body's axes in the world); in xd, the velocity and
 *    the three angles' rates; in f, the force [N] and the moment [N m]
 *    about the reference point, world axes. Unlike MoorDyn's, they are
 *    the lines' (and joined bodies') only: the body's own weight,
 *    buoyancy and inertia are the host's (docs/coupling.md);
 *  - MoorDyn_Step's forces are the lines' forces on the coupled points,
 *    their mean over the step (CableSim_GetMeanForces).
 *
 * The functions return MOORDYN_SUCCESS (0) or a negative code; the handle
 * getters return NULL on an error. CableSim_ErrorMessage() (cablesim_couple.h)
 * says why, naming the argument. */

#ifdef __cplusplus
extern "C" {
#endif

typedef struct CableSimMoorDynSystem* MoorDyn;
typedef struct CableSimMoorDynLine* MoorDynLine;
typedef struct CableSimMoorDynPoint* MoorDynPoint;

enum {
  MOORDYN_SUCCESS = 0,
  MOORDYN_INVALID_INPUT_FILE = -1, /* the file is not a usable deck or scene */
  MOORDYN_INVALID_INPUT = -3,      /* a bad argument (CableSim_ErrorMessage names it) */
  MOORDYN_NAN_ERROR = -4,          /* the lines could not be advanced */
  MOORDYN_INVALID_VALUE = -6,      /* called in the wrong state */
  MOORDYN_UNHANDLED_ERROR = -255
};

/* Reads a MoorDyn v2 deck (or a cablesim scene: JSON or text format) and
 * builds the model. NULL on error. */
MoorDyn MoorDyn_Create(const char* infilename);
/* 6 per coupled body and 3 per coupled point. */
int MoorDyn_NCoupledDOF(MoorDyn system, unsigned int* n);
/* x, xd: the coupled bodies' poses and rates, then the coupled points'
 * positions [m] and velocities [m/s] at t = 0, in the order above. The lines start from their static
 * equilibrium with the points there when the scene asks for it (a deck
 * always does: its TmaxIC). */
int MoorDyn_Init(MoorDyn system, const double* x, const double* xd);
/* From *t to *t + *dt, the coupled points moving linearly to x, xd (the
 * bodies' centres linearly, their orientations by slerp); f gets the lines'
 * forces on them [N] (and the bodies' moments [N m]). On success *t is the
 * new time. */
int MoorDyn_Step(MoorDyn system, const double* x, const double* xd, double* f, double* t,
                 double* dt);
/* Frees the system and its handles (NULL is allowed). */
int MoorDyn_Close(MoorDyn system);

int MoorDyn_GetNumberLines(MoorDyn system, unsigned int* n);
/* Line l, from 1. NULL if there is none. */
MoorDynLine MoorDyn_GetLine(MoorDyn system, unsigned int l);
int MoorDyn_GetLineNumberNodes(MoorDynLine line, unsigned int* n);
int MoorDyn_GetLineNodePos(MoorDynLine line, unsigned int i, double pos[3]);
/* The tension vector at node i [N]: the axial force (the section force the
 * elements hold there, docs/reference/output.md) along the line's tangent
 * from end A towards end B. */
int MoorDyn_GetLineNodeTen(MoorDynLine line, unsigned int i, double ten[3]);
/* The axial force at end B [N] (the deck's FairTen). */
int MoorDyn_GetLineFairTen(MoorDynLine line, double* t);

int MoorDyn_GetNumberPoints(MoorDyn system, unsigned int* n);
/* The point with the deck's ID `id` (a cablesim scene: the id-th joint name
 * in scene order, from 1). NULL if there is none. */
MoorDynPoint MoorDyn_GetPoint(MoorDyn system, unsigned int id);
/* A coupled point's position as last given (Init or Step; before Init, where
 * the deck places it); a fixed point's where it is held. */
int MoorDyn_GetPointPos(MoorDynPoint point, double pos[3]);

#ifdef __cplusplus
}
#endif

#endif /* CABLESIM_COUPLE_MOORDYN_MOORDYN2_H_ */
