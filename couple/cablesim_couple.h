#ifndef CABLESIM_COUPLE_CABLESIM_COUPLE_H_
#define CABLESIM_COUPLE_CABLESIM_COUPLE_H_

/* libcablesim_couple: cablesim's lines driven step by step by a host
 * program, from C (or anything that calls C). The functions map one to one
 * onto those of MoorDyn's C interface, so a host written against it changes
 * the names and the link line only:
 *
 *   CableSim_Create(file)                 MoorDyn_Create
 *   CableSim_NCoupledDOF(sys, &n)         MoorDyn_NCoupledDOF
 *   CableSim_Init(sys, x, xd)             MoorDyn_Init
 *   CableSim_Step(sys, x, xd, f, &t, &dt) MoorDyn_Step
 *   CableSim_GetNumberLines(sys, &n)      MoorDyn_GetNumberLines
 *   CableSim_GetLineNumberNodes(...)      MoorDyn_GetLineNumberNodes
 *   CableSim_GetLineNodePos(...)          MoorDyn_GetLineNodePos
 *   CableSim_GetLineTension(...)          MoorDyn_GetLineNodeTen (the tension's magnitude)
 *   CableSim_Close(sys)                   MoorDyn_Close
 *
 * The scene file is a cablesim scene (JSON or text format) whose coupled
 * supports are joints to ground with "coupled": true. The coupled degrees
 * of freedom are 3 per coupled support (x, y, z), in scene order of the
 * joints: x, xd and f have 3 n entries (NULL allowed when n is 0).
 * Coupled bodies (bodies with "coupled": true) are set apart:
 * CableSim_SetBodyKinematics before Init and each Step, and
 * CableSim_GetBodyForces after. See docs/coupling.md.
 *
 * Every function but Create returns CABLESIM_OK (0) or an error code; on an
 * error CableSim_ErrorMessage() (this thread's last error) says why and
 * names the argument ("x[1].z: must be finite (got nan)"). An input error
 * leaves the system as it was. A step that fails (the lines' Newton
 * iterations do not converge even at the smallest sub-step) returns
 * CABLESIM_STEP_FAILED and the system refuses further steps.
 *
 * A host written against MoorDyn v2's C function names can keep them:
 * couple/moordyn/MoorDyn2.h declares them over this library. */

#ifdef __cplusplus
extern "C" {
#endif

typedef struct CableSimSystemImpl* CableSimSystem;

enum {
  CABLESIM_OK = 0,
  CABLESIM_INVALID_ARGUMENT = 1, /* bad input: names the argument */
  CABLESIM_INVALID_SCENE = 2,    /* the file is not a usable scene */
  CABLESIM_STEP_FAILED = 3,      /* the lines could not be advanced */
  CABLESIM_WRONG_STATE = 4       /* not initialised yet, or failed */
};

/* Reads and checks the scene, builds the model. NULL on error (see
 * CableSim_ErrorMessage). */
CableSimSystem CableSim_Create(const char* scene_file);
/* The number of coupled degrees of freedom, 3 per coupled support. */
int CableSim_NCoupledDOF(CableSimSystem sys, unsigned int* n);
/* x, xd: the coupled points' positions [m] and velocities [m/s] at t = 0.
 * With solver.initial_state STATIC, the lines start from their static
 * equilibrium with the points there; otherwise x must be the scene's
 * points. */
int CableSim_Init(CableSimSystem sys, const double* x, const double* xd);
/* Advances from *t (the system's time) to *t + *dt with x, xd the coupled
 * points' kinematics at *t + *dt (the points move linearly in between,
 * with cablesim's own steps inside); f receives the forces [N] the lines
 * exert on the points, their mean over the step (as
 * CableSim_GetMeanForces: the impulse over the step divided by dt, which
 * converges where the end forces do not; CableSim_GetForces gives the end
 * forces). On success *t is the new time. */
int CableSim_Step(CableSimSystem sys, const double* x, const double* xd, double* f, double* t,
                  double* dt);
/* f: the forces [N] on the coupled points at the system's time (after
 * CableSim_Init: those of the initial state; after a step: at its end). */
int CableSim_GetForces(CableSimSystem sys, double* f);
/* f: the forces' mean over the last step [N] (their impulse over the step
 * divided by it; after CableSim_Init: the initial forces). It carries the
 * impulse the lines' mass next to the points takes when their velocity
 * changes at the start of a step, which the end forces miss: a host that
 * integrates momentum uses these (docs/coupling.md). */
int CableSim_GetMeanForces(CableSimSystem sys, double* f);
/* Lines are the scene's cables, 0-based in scene order. */
int CableSim_GetNumberLines(CableSimSystem sys, unsigned int* n);
int CableSim_GetLineNumberNodes(CableSimSystem sys, unsigned int line, unsigned int* n);
int CableSim_GetLineNodePos(CableSimSystem sys, unsigned int line, unsigned int node,
                            double pos[3]);
/* The tension [N] at node `node`: the axial force, the section force the
 * elements hold there under the cable's own axial law (negative in
 * compression; docs/reference/output.md, "Tension along a line"). */
int CableSim_GetLineTension(CableSimSystem sys, unsigned int line, unsigned int node,
                            double* tension);
/* Coupled bodies (bodies with "coupled": true, 6 degrees of freedom), in
 * scene order of the bodies, 0-based. A body's pose is its centre of mass
 * [m] and its orientation, a unit quaternion q = (w, x, y, z) whose
 * rotation matrix's columns are the body's local x, y, z axes in the world
 * (absolute: the scene's own pose is CableSim_GetBodyScenePose). */
int CableSim_NCoupledBodies(CableSimSystem sys, unsigned int* n);
int CableSim_GetBodyScenePose(CableSimSystem sys, unsigned int body, double pos[3],
                              double q[4]);
/* Sets body `body`'s kinematics for the next CableSim_Init or
 * CableSim_Step (until then they are the scene's pose at rest): its
 * centre's position pos [m] and velocity vel [m/s], its orientation q
 * (w, x, y, z; unit to 1e-6) and angular velocity omega [rad/s], world
 * axes. Inside a step the centre moves linearly and the body turns about
 * the fixed axis of q1 q0^-1 at a constant rate (slerp); the velocities
 * are used at Init only, as the points'. CABLESIM_INVALID_ARGUMENT naming
 * the argument (a body that does not exist, a non-finite value, a q that
 * is not unit) leaves the staged kinematics as they were. */
int CableSim_SetBodyKinematics(CableSimSystem sys, unsigned int body, const double pos[3],
                               const double q[4], const double vel[3], const double omega[3]);
/* The force [N] and the moment [N m] (about the centre, world axes) that
 * the cables and bodies joined to body `body` exert on it: their mean over
 * the last step (impulse / dt, as CableSim_GetMeanForces), and at the
 * system's time. */
int CableSim_GetBodyForces(CableSimSystem sys, unsigned int body, double force[3],
                           double moment[3]);
int CableSim_GetBodyEndForces(CableSimSystem sys, unsigned int body, double force[3],
                              double moment[3]);
/* The work the host has done on the lines since Init [J]: per step, minus
 * the mean forces times the points' displacements and minus the bodies'
 * mean moments times their rotation vectors (docs/coupling.md, "Energy at
 * the fairleads"). */
int CableSim_GetHostWork(CableSimSystem sys, double* work);
/* The scene's mechanical energy now [J] (without the coupled bodies' own
 * kinetic and gravity energy) and the work done against damping since Init
 * [J]: host work = energy - energy at Init + dissipated, up to the
 * integrator's own dissipation. */
int CableSim_GetEnergy(CableSimSystem sys, double* energy, double* dissipated);
/* The system's time [s]. */
int CableSim_GetTime(CableSimSystem sys, double* t);
/* Frees the system (NULL is allowed). */
int CableSim_Close(CableSimSystem sys);
/* This thread's last error message ("" after success). */
const char* CableSim_ErrorMessage(void);

#ifdef __cplusplus
}
#endif

#endif /* CABLESIM_COUPLE_CABLESIM_COUPLE_H_ */
