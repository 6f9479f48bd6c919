/* march.h: the steady lumped rigid-link problem solved by marching from the
 * free ends to the tow point, with shooting on the free-end positions
 * (internal; doc/model.md section 5, doc/equilibrium.md).
 *
 * Given the position of every free end, each link's direction and tension
 * follow from its lower node's force balance, one small root per link,
 * free ends first. Where branches meet, and at the tow point, the marched
 * positions must agree: the mismatches are the residual of a root problem
 * in the 3 * (number of free ends) unknowns. A straight tow that stays on
 * one side of the surface does not depend on those positions at all (the
 * shape only translates), so one correction closes it exactly; turns and
 * surface crossings take a few Powell hybrid iterations (GSL).
 * Elastic links are marched too: their length follows their tension.
 * Bending (EI > 0) couples a node to the link above it and is not marched.
 */
#ifndef TOWSTAB_MARCH_H
#define TOWSTAB_MARCH_H

#include "towstab/error.h"
#include "towstab/kernel.h"
#include "towstab/system.h"

typedef struct tsi_march tsi_march;

tsi_march *tsi_march_alloc(const ts_system *sys, ts_err *err);
void tsi_march_free(tsi_march *m);

/* Extra known loads at the nodes, F[3 nnodes] (N, M frame; copied), or
 * NULL for none: a vehicle's steady pull on its node for a starting
 * guess. Vehicles' own loads are otherwise left out of the march (it has
 * no attitudes); their child cables start at their nodes. */
int tsi_march_set_loads(tsi_march *m, const double *F);

/* The force (N, M) the vehicle at `node` pulls it with when its joint
 * is at r[3] (m, M): TS_OK, or a code that stops the march. */
typedef int (*tsi_march_pull_fn)(void *ctx, int node, const double r[3],
                                 double F[3]);

/* Vehicles in the march, at attitudes the caller holds: pull gives each
 * vehicle's load on its node from the node's position; off[3 nlinks]
 * (m, M; the caller's, read at every march) is where a link that starts
 * on a vehicle starts relative to the vehicle's node, R (P - A), and 0
 * for the others. NULL pull: vehicles left out, their child cables
 * starting at their nodes. */
void tsi_march_set_vehicles(tsi_march *m, tsi_march_pull_fn pull, void *ctx,
                            const double *off);

/* Node 0's position r[3] (m, M), where the cables from it must end:
 * sys->tow.point until set; a towing vehicle's tow point where its state
 * places it. The march's first guesses (fresh, tsi_march_warm) hang
 * from it too. */
void tsi_march_set_root(tsi_march *m, const double r[3]);

/* Number of shooting unknowns and residuals: 3 per free end. */
int tsi_march_nunknown(const tsi_march *m);

/* March for free-end positions x[nunknown] (m) under frame f; writes the
 * mismatches e[nunknown] (m). Returns TS_OK, TS_ECONV (a link's direction
 * root failed) or TS_ESINGULAR (a link with no load to align with). */
int tsi_march_eval(tsi_march *m, const ts_frame *f, const double x[],
                   double e[], ts_err *err);

/* Solve the shooting problem: on entry x is a guess (or NULL content
 * filled by a hanging guess when *fresh), on exit the free-end positions
 * with max |e| <= pos_tol. Counts iterations and marches. */
int tsi_march_solve(tsi_march *m, const ts_frame *f, double x[], int fresh,
                    double pos_tol, int max_iter, int *iterations,
                    long *marches, ts_err *err);

/* A warm start from a shape: link directions[3 nlinks] (unit vectors,
 * e.g. a neighbouring equilibrium's) become the local roots' first
 * guesses, and x[nunknown] the free-end positions they give from the tow
 * point (unstretched lengths). Pass x to tsi_march_solve with fresh 0. */
void tsi_march_warm(tsi_march *m, const double *directions, double x[]);

/* Results of the last march: link directions [3 nlinks], tensions, node
 * positions [3 nnodes] (m, M). */
const double *tsi_march_directions(const tsi_march *m);
const double *tsi_march_positions(const tsi_march *m);
const double *tsi_march_tensions(const tsi_march *m);

/* Strains e = T / EA of the last march into e[nlinks] (0 for rigid
 * links). */
void tsi_march_strains(const tsi_march *m, double *e);

/* Condition number (1-norm) of the shooting Jacobian at the last solve's
 * solution (the translation Jacobian where translation corrections closed
 * it, else a forward-difference one: 3 marches per free end, counted in
 * *marches, which leave the stored shape at a perturbed point: read the
 * solution out first), and the free-end position error it implies,
 * |J^-1| |mismatch| (m). NaN when it cannot be formed. */
int tsi_march_condition(tsi_march *m, double *condition, double *shape_error,
                        long *marches);

/* The 1-norm (largest column sum of magnitudes) of the row-major n x n
 * matrix a. */
double tsi_norm1(const double *a, int n);

/* Largest |mismatch| of the last march, m. */
double tsi_march_mismatch(const tsi_march *m);

#endif
