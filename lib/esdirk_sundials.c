/* lib/esdirk_sundials.c: the L-stable ESDIRK 5(4) stepper of lib/esdirk.h,
 * built as a module of its own (towstab-sundials.so) that the library
 * (lib/esdirk.c) opens only when a run steps with esdirk or bdf, so that
 * other runs do not load SUNDIALS (doc/performance.md, "Start-up"). It
 * exports one table (esdirk_module.h) whose entries are the functions of
 * lib/esdirk.h.
 *
 * SUNDIALS ARKODE's ARKStep, fully implicit (no explicit part), table
 * ARKODE_ARK548L2SA_DIRK_8_4_5 (Kennedy & Carpenter, "Higher-order
 * additive Runge-Kutta schemes for ordinary differential equations",
 * Appl. Numer. Math. 136, 2019), ARKODE's default error controller and
 * modified Newton iteration. ARKODE drives a linear solver through the
 * SUNLinearSolver interface; Debian's SUNDIALS has no LAPACK-backed dense
 * solver, so the one here is a SUNLinearSolver of our own whose setup is
 * LAPACK's blocked dgetrf (with the system's BLAS) and whose solve is
 * dgetrs (blocked, through the system's BLAS, where SUNDIALS' own dense LU
 * is column by column).
 *
 * Three settings beyond ARKODE's defaults, found by test_esdirk and the
 * elastic benchmark (test/bench/bench_elastic_sim.c):
 *  - the Newton convergence-rate estimate is not carried over between
 *    stages (ARKStepSetNonlinCRDown 1): ARKODE otherwise reuses a rate
 *    measured against an earlier matrix, and on nearly linear problems
 *    accepts a stage after one iteration with an out-of-date matrix (errors
 *    up to 1000 times the tolerance);
 *  - ARKODE evaluates f once more at each accepted stage, outside Newton,
 *    and takes a refusal there as fatal (ARK_UNREC_RHSFUNC_ERR); the kernel
 *    refuses states near the angle chart's singularity or with a collapsed
 *    elastic link, which is a matter of step length: the step is retried
 *    from the last accepted state with a first step of a quarter of the
 *    last one, up to RETRIES times;
 *  - up to NEWTON_ITERS (10) Newton iterations per stage instead of 3: the
 *    modified Newton iteration on a matrix some steps old converges
 *    linearly, and on an elastic cable it often needed a fourth
 *    iteration; with 3 each such stage was a convergence failure, a new
 *    Jacobian and a shorter step (Kamman ex. 1 elastic at 10 links, a
 *    heave step: 428 steps, 465 failures, 466 Jacobians at rtol 1e-6,
 *    atol 1e-8; with 10: 70 steps, 2 failures, 2 Jacobians, the same
 *    answer to 2e-8 m; the benchmark's errors against its reference did
 *    not grow).
 *
 * The same stepper can be SUNDIALS CVODE's variable-step BDF instead
 * (tsi_esdirk_alloc_method, bdf = 1: `--integrator bdf`), with the same
 * Newton matrix I - gamma J (CVODE's gamma is h times its BDF
 * coefficient), the same structured solver and the same retries. Its
 * order is capped at BDF_MAX_ORDER = 2: BDF2 is A- and L-stable, while
 * BDF3 to BDF5 are unstable in a bounded region next to the imaginary
 * axis, where an elastic cable's lightly damped axial modes sit at
 * moderate steps. One Newton solve per step instead of seven stages:
 * cheaper per step, more steps (order 2 against 5); measured in
 * doc/performance.md ("Simulating a stiff elastic cable").
 *
 * ARKODE reports failures through an error handler: the last message is
 * kept in the stepper (nothing is printed) and handed on in ts_err.
 * Written against SUNDIALS 6 (Debian 12); every object hangs off a
 * SUNContext owned by the stepper, so steppers are independent. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <arkode/arkode_arkstep.h>
#include <cvode/cvode.h>
#include <cvode/cvode_ls.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_linearsolver.h>
#include <sunmatrix/sunmatrix_dense.h>

#include "esdirk.h"
#include "esdirk_module.h"
#include "lapack.h"

/* Retries of a step whose accepted stage f refused (see above). */
#define RETRIES 4
/* Newton iterations allowed per stage (ARKODE's default: 3; see above). */
#define NEWTON_ITERS 10
/* The BDF's highest order: 2, A- and L-stable (see the head of the
 * file). */
#define BDF_MAX_ORDER 2

struct tsi_esdirk_impl {
    int n;
    tsi_ode_fn f;
    tsi_ode_jac jac;
    tsi_ode_lsys lsys;     /* structured solver (setup NULL: dense jac) */
    void *params;
    SUNContext ctx;
    N_Vector y, yi;       /* state; interpolated output */
    SUNMatrix A;
    SUNLinearSolver ls;
    void *mem;
    int bdf;                /* CVODE's BDF instead of ARKODE */
    double h_init;
    char msg[400];          /* ARKODE's last error message */
    /* Counters of earlier runs (ARKStepReInit zeroes ARKODE's own). */
    long steps0, rejected0, setups0;
};

/* --- The LAPACK dense linear solver ----------------------------------- */

typedef struct lu_content {
    int n;
    double *lu;   /* [n n] column-major factors of I - gamma h J */
    int *piv;     /* [n] */
} lu_content;

static SUNLinearSolver_Type lu_gettype(SUNLinearSolver S)
{
    (void)S;
    return SUNLINEARSOLVER_DIRECT;
}

static SUNLinearSolver_ID lu_getid(SUNLinearSolver S)
{
    (void)S;
    return SUNLINEARSOLVER_CUSTOM;
}

/* Factor the iteration matrix: > 0 (recoverable: ARKODE retries with a
 * shorter step) when it is singular. */
static int lu_setup(SUNLinearSolver S, SUNMatrix A)
{
    lu_content *c = S->content;
    int n = c->n, info = 0;
    memcpy(c->lu, SUNDenseMatrix_Data(A), (size_t)n * (size_t)n *
           sizeof(double));
    dgetrf_(&n, &n, c->lu, &n, c->piv, &info);
    return info == 0 ? 0 : (info > 0 ? 1 : -1);
}

static int lu_solve(SUNLinearSolver S, SUNMatrix A, N_Vector x, N_Vector b,
                    sunrealtype tol)
{
    (void)A;
    (void)tol;
    lu_content *c = S->content;
    int n = c->n, one = 1, info = 0;
    N_VScale(1.0, b, x);
    dgetrs_("N", &n, &one, c->lu, &n, c->piv, N_VGetArrayPointer(x), &n,
            &info, 1);
    return info == 0 ? 0 : -1;
}

static int lu_free(SUNLinearSolver S)
{
    if (!S)
        return 0;
    lu_content *c = S->content;
    if (c) {
        free(c->lu);
        free(c->piv);
        free(c);
        S->content = NULL;
    }
    SUNLinSolFreeEmpty(S);
    return 0;
}

static SUNLinearSolver lu_new(int n, SUNContext ctx)
{
    SUNLinearSolver S = SUNLinSolNewEmpty(ctx);
    if (!S)
        return NULL;
    lu_content *c = calloc(1, sizeof *c);
    S->content = c;
    S->ops->gettype = lu_gettype;
    S->ops->getid = lu_getid;
    S->ops->setup = lu_setup;
    S->ops->solve = lu_solve;
    S->ops->free = lu_free;
    if (!c) {
        SUNLinSolFreeEmpty(S);
        return NULL;
    }
    c->n = n;
    c->lu = malloc((size_t)n * (size_t)n * sizeof(double));
    c->piv = malloc((size_t)n * sizeof(int));
    if (!c->lu || !c->piv) {
        lu_free(S);
        return NULL;
    }
    return S;
}

/* --- The structured solver ------------------------------------------ */

/* With a structured solver ARKODE still wants a SUNMatrix to hand to its
 * linear-system function and the solver; it holds nothing (the solver's
 * callbacks keep their own factors), and ARKODE, given a linear-system
 * function of ours, calls none of its operations but these. */
static SUNMatrix_ID sm_getid(SUNMatrix A)
{
    (void)A;
    return SUNMATRIX_CUSTOM;
}

static void sm_destroy(SUNMatrix A)
{
    SUNMatFreeEmpty(A);
}

static SUNMatrix sm_new(SUNContext ctx)
{
    SUNMatrix A = SUNMatNewEmpty(ctx);
    if (!A)
        return NULL;
    A->ops->getid = sm_getid;
    A->ops->destroy = sm_destroy;
    return A;
}

/* The solver: setup is done in linsys (it knows t, y and gamma); solve
 * calls the callback. */
static int ss_setup(SUNLinearSolver S, SUNMatrix A)
{
    (void)S;
    (void)A;
    return 0;
}

static int ss_solve(SUNLinearSolver S, SUNMatrix A, N_Vector x, N_Vector b,
                    sunrealtype tol)
{
    (void)A;
    (void)tol;
    tsi_esdirk_impl *s = S->content;
    int rc = s->lsys.solve(N_VGetArrayPointer(x), N_VGetArrayPointer(b),
                           s->params);
    return rc == 0 ? 0 : (rc > 0 ? 1 : -1);
}

static int ss_free(SUNLinearSolver S)
{
    if (S)
        SUNLinSolFreeEmpty(S);
    return 0;
}

static SUNLinearSolver ss_new(tsi_esdirk_impl *s, SUNContext ctx)
{
    SUNLinearSolver S = SUNLinSolNewEmpty(ctx);
    if (!S)
        return NULL;
    S->content = s;
    S->ops->gettype = lu_gettype;
    S->ops->getid = lu_getid;
    S->ops->setup = ss_setup;
    S->ops->solve = ss_solve;
    S->ops->free = ss_free;
    return S;
}

/* ARKODE's linear-system function: re-evaluate J unless jok, factor
 * I - gamma J. */
static int linsys(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix A,
                  SUNMatrix M, sunbooleantype jok, sunbooleantype *jcur,
                  sunrealtype gamma, void *ud, N_Vector t1, N_Vector t2,
                  N_Vector t3)
{
    (void)fy;
    (void)A;
    (void)M;
    (void)t1;
    (void)t2;
    (void)t3;
    tsi_esdirk_impl *s = ud;
    int cur = 0;
    int rc = s->lsys.setup(t, N_VGetArrayPointer(y), gamma, jok, &cur,
                           s->params);
    *jcur = cur ? SUNTRUE : SUNFALSE;
    return rc;
}

static int cv_linsys(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix A,
                     sunbooleantype jok, sunbooleantype *jcur,
                     sunrealtype gamma, void *ud, N_Vector t1, N_Vector t2,
                     N_Vector t3)
{
    return linsys(t, y, fy, A, NULL, jok, jcur, gamma, ud, t1, t2, t3);
}

/* --- ARKODE callbacks ------------------------------------------------- */

static int rhs(sunrealtype t, N_Vector y, N_Vector ydot, void *ud)
{
    tsi_esdirk_impl *s = ud;
    return s->f(t, N_VGetArrayPointer(y), N_VGetArrayPointer(ydot),
                s->params);
}

static int jacobian(sunrealtype t, N_Vector y, N_Vector fy, SUNMatrix J,
                    void *ud, N_Vector t1, N_Vector t2, N_Vector t3)
{
    (void)fy;
    (void)t1;
    (void)t2;
    (void)t3;
    tsi_esdirk_impl *s = ud;
    return s->jac(t, N_VGetArrayPointer(y), SUNDenseMatrix_Data(J),
                  s->params);
}

static void on_error(int code, const char *module, const char *function,
                     char *msg, void *ud)
{
    (void)code;
    (void)module;
    (void)function;
    tsi_esdirk_impl *s = ud;
    snprintf(s->msg, sizeof s->msg, "%s", msg ? msg : "");
}

/* --- The stepper ------------------------------------------------------ */

static void stepper_get_stats(const tsi_esdirk_impl *s, tsi_esdirk_stats *st);

static void stepper_free(tsi_esdirk_impl *s)
{
    if (!s)
        return;
    if (s->mem && s->bdf)
        CVodeFree(&s->mem);
    else if (s->mem)
        ARKStepFree(&s->mem);
    if (s->ls)
        SUNLinSolFree(s->ls);
    if (s->A)
        SUNMatDestroy(s->A);
    if (s->y)
        N_VDestroy(s->y);
    if (s->yi)
        N_VDestroy(s->yi);
    if (s->ctx)
        SUNContext_Free(&s->ctx);
    free(s);
}

static tsi_esdirk_impl *
stepper_alloc_method(int n, tsi_ode_fn f, tsi_ode_jac jac,
                     const tsi_ode_lsys *lsys, void *params, double rtol,
                     double atol, double h_init, int bdf, ts_err *err)
{
    tsi_esdirk_impl *s = calloc(1, sizeof *s);
    if (!s) {
        ts_fail(err, TS_ENOMEM, "esdirk: out of memory");
        return NULL;
    }
    s->n = n;
    s->f = f;
    s->jac = jac;
    if (lsys)
        s->lsys = *lsys;
    s->params = params;
    s->h_init = h_init;
    if (SUNContext_Create(NULL, &s->ctx) != 0 ||
        !(s->y = N_VNew_Serial(n, s->ctx)) ||
        !(s->yi = N_VNew_Serial(n, s->ctx)) ||
        !(s->A = lsys ? sm_new(s->ctx) : SUNDenseMatrix(n, n, s->ctx)) ||
        !(s->ls = lsys ? ss_new(s, s->ctx) : lu_new(n, s->ctx))) {
        stepper_free(s);
        ts_fail_nomem(err, 2 * 8.0 * n * (double)n, "fewer links, or an "
                      "explicit integrator (rk8pd)", "esdirk: out of memory "
                      "for the %d x %d Jacobian and its LU", n, n);
        return NULL;
    }
    N_VConst(0.0, s->y);
    s->bdf = bdf;
    if (bdf) {
        int bad = 0;
        s->mem = CVodeCreate(CV_BDF, s->ctx);
        if (!s->mem) {
            stepper_free(s);
            ts_fail(err, TS_ENOMEM, "bdf: CVODE could not be set up for %d "
                    "states", n);
            return NULL;
        }
        bad |= CVodeInit(s->mem, rhs, 0.0, s->y);
        bad |= CVodeSetErrHandlerFn(s->mem, on_error, s);
        bad |= CVodeSetUserData(s->mem, s);
        bad |= CVodeSStolerances(s->mem, rtol, atol);
        bad |= CVodeSetLinearSolver(s->mem, s->ls, s->A);
        if (lsys)
            bad |= CVodeSetLinSysFn(s->mem, cv_linsys);
        else
            bad |= CVodeSetJacFn(s->mem, jacobian);
        bad |= CVodeSetInitStep(s->mem, h_init);
        bad |= CVodeSetMaxOrd(s->mem, BDF_MAX_ORDER);
        bad |= CVodeSetMaxNonlinIters(s->mem, NEWTON_ITERS);
        if (bad) {
            ts_fail(err, TS_EINVAL, "bdf: CVODE refused the options (rtol "
                    "%g, atol %g, first step %g s): %s", rtol, atol, h_init,
                    s->msg);
            stepper_free(s);
            return NULL;
        }
        return s;
    }
    s->mem = ARKStepCreate(NULL, rhs, 0.0, s->y, s->ctx);
    if (!s->mem) {
        stepper_free(s);
        ts_fail(err, TS_ENOMEM, "esdirk: ARKODE could not be set up for %d "
                "states", n);
        return NULL;
    }
    int bad = 0;
    bad |= ARKStepSetErrHandlerFn(s->mem, on_error, s);
    bad |= ARKStepSetUserData(s->mem, s);
    bad |= ARKStepSStolerances(s->mem, rtol, atol);
    bad |= ARKStepSetTableNum(s->mem, ARKODE_ARK548L2SA_DIRK_8_4_5,
                              ARKODE_ERK_NONE);
    bad |= ARKStepSetLinearSolver(s->mem, s->ls, s->A);
    if (lsys)
        bad |= ARKStepSetLinSysFn(s->mem, linsys);
    else
        bad |= ARKStepSetJacFn(s->mem, jacobian);
    bad |= ARKStepSetInitStep(s->mem, h_init);
    bad |= ARKStepSetNonlinCRDown(s->mem, 1.0);
    bad |= ARKStepSetMaxNonlinIters(s->mem, NEWTON_ITERS);
    if (lsys && lsys->linear)
        bad |= ARKStepSetLinear(s->mem, 0); /* J constant in time */
    if (bad) {
        ts_fail(err, TS_EINVAL, "esdirk: ARKODE refused the options (rtol "
                "%g, atol %g, first step %g s): %s", rtol, atol, h_init,
                s->msg);
        stepper_free(s);
        return NULL;
    }
    return s;
}

static int stepper_reset(tsi_esdirk_impl *s, double t, const double y[],
                         ts_err *err)
{
    long v = 0;
    if (s->bdf) {
        tsi_esdirk_stats st;
        stepper_get_stats(s, &st);
        s->steps0 = st.steps;
        s->rejected0 = st.rejected;
        s->setups0 = st.setups;
        memcpy(N_VGetArrayPointer(s->y), y, (size_t)s->n * sizeof(double));
        if (CVodeReInit(s->mem, t, s->y) != 0)
            return ts_fail(err, TS_EINTEGRATOR, "bdf: restart at t = %.9g s "
                           "failed: %s", t, s->msg);
        return TS_OK;
    }
    if (ARKStepGetNumSteps(s->mem, &v) == 0)
        s->steps0 += v;
    long etf = 0, ncf = 0;
    ARKStepGetNumErrTestFails(s->mem, &etf);
    ARKStepGetNumNonlinSolvConvFails(s->mem, &ncf);
    s->rejected0 += etf + ncf;
    if (ARKStepGetNumLinSolvSetups(s->mem, &v) == 0)
        s->setups0 += v;
    memcpy(N_VGetArrayPointer(s->y), y, (size_t)s->n * sizeof(double));
    if (ARKStepReInit(s->mem, NULL, rhs, t, s->y) != 0)
        return ts_fail(err, TS_EINTEGRATOR, "esdirk: restart at t = %.9g s "
                       "failed: %s", t, s->msg);
    return TS_OK;
}

/* CVODE's step, with the same retries as ARKODE's (see the head of the
 * file): a refused right-hand side restarts from the last accepted state
 * with a quarter of the last step. */
static int bdf_step(tsi_esdirk_impl *s, double tstop, double *t,
                    double y[], ts_err *err)
{
    sunrealtype tret = *t, h = 0;
    int flag = CVodeSetStopTime(s->mem, tstop);
    if (flag == 0)
        flag = CVode(s->mem, tstop, s->y, &tret, CV_ONE_STEP);
    CVodeGetLastStep(s->mem, &h);
    for (int r = 0; r < RETRIES && (flag == CV_UNREC_RHSFUNC_ERR ||
                                    flag == CV_REPTD_RHSFUNC_ERR);
         r++) {
        h = (h > 0 ? h : s->h_init) / 4.0;
        memcpy(N_VGetArrayPointer(s->y), y, (size_t)s->n * sizeof(double));
        s->msg[0] = '\0';
        flag = CVodeReInit(s->mem, *t, s->y);
        if (flag == 0)
            flag = CVodeSetInitStep(s->mem, h);
        if (flag == 0)
            flag = CVodeSetStopTime(s->mem, tstop);
        if (flag == 0)
            flag = CVode(s->mem, tstop, s->y, &tret, CV_ONE_STEP);
        CVodeSetInitStep(s->mem, s->h_init);
    }
    if (flag < 0) {
        char *name = CVodeGetReturnFlagName(flag);
        ts_fail(err, TS_EINTEGRATOR, "bdf failed at t = %.9g s (%s): %s", *t,
                name ? name : "?", s->msg[0] ? s->msg : "no reason given");
        free(name);
        return TS_EINTEGRATOR;
    }
    *t = tret;
    memcpy(y, N_VGetArrayPointer(s->y), (size_t)s->n * sizeof(double));
    return TS_OK;
}

static int stepper_step(tsi_esdirk_impl *s, double tstop, double *t,
                        double y[], ts_err *err)
{
    s->msg[0] = '\0';
    sunrealtype tret = *t;
    if (s->bdf)
        return bdf_step(s, tstop, t, y, err);
    int flag = ARKStepSetStopTime(s->mem, tstop);
    if (flag == 0)
        flag = ARKStepEvolve(s->mem, tstop, s->y, &tret, ARK_ONE_STEP);
    sunrealtype h = 0;
    ARKStepGetLastStep(s->mem, &h);
    for (int r = 0; r < RETRIES && flag == ARK_UNREC_RHSFUNC_ERR; r++) {
        /* Back to the last accepted state, with a shorter first step. */
        h = (h > 0 ? h : s->h_init) / 4.0;
        memcpy(N_VGetArrayPointer(s->y), y, (size_t)s->n * sizeof(double));
        s->msg[0] = '\0';
        flag = ARKStepSetInitStep(s->mem, h);
        if (flag == 0)
            flag = ARKStepReset(s->mem, *t, s->y);
        if (flag == 0)
            flag = ARKStepSetStopTime(s->mem, tstop);
        if (flag == 0)
            flag = ARKStepEvolve(s->mem, tstop, s->y, &tret, ARK_ONE_STEP);
        ARKStepSetInitStep(s->mem, s->h_init);
    }
    if (flag < 0) {
        char *name = ARKStepGetReturnFlagName(flag);
        ts_fail(err, TS_EINTEGRATOR, "esdirk failed at t = %.9g s (%s): %s",
                *t, name ? name : "?", s->msg[0] ? s->msg : "no reason given");
        free(name);
        return TS_EINTEGRATOR;
    }
    *t = tret;
    memcpy(y, N_VGetArrayPointer(s->y), (size_t)s->n * sizeof(double));
    return TS_OK;
}

static int stepper_interpolate(tsi_esdirk_impl *s, double t, double y[],
                               ts_err *err)
{
    if ((s->bdf ? CVodeGetDky(s->mem, t, 0, s->yi)
                : ARKStepGetDky(s->mem, t, 0, s->yi)) != 0)
        return ts_fail(err, TS_EINTEGRATOR, "esdirk: no solution to "
                       "interpolate at t = %.9g s: %s", t, s->msg);
    memcpy(y, N_VGetArrayPointer(s->yi), (size_t)s->n * sizeof(double));
    return TS_OK;
}

static void stepper_get_stats(const tsi_esdirk_impl *s, tsi_esdirk_stats *st)
{
    long steps = 0, etf = 0, ncf = 0, setups = 0;
    sunrealtype hl = 0, hc = 0;
    if (s->bdf) {
        CVodeGetNumSteps(s->mem, &steps);
        CVodeGetNumErrTestFails(s->mem, &etf);
        CVodeGetNumNonlinSolvConvFails(s->mem, &ncf);
        CVodeGetNumLinSolvSetups(s->mem, &setups);
        CVodeGetLastStep(s->mem, &hl);
        CVodeGetCurrentStep(s->mem, &hc);
        st->steps = s->steps0 + steps;
        st->rejected = s->rejected0 + etf + ncf;
        st->setups = s->setups0 + setups;
        st->h_last = hl;
        st->h_next = hc;
        return;
    }
    ARKStepGetNumSteps(s->mem, &steps);
    ARKStepGetNumErrTestFails(s->mem, &etf);
    ARKStepGetNumNonlinSolvConvFails(s->mem, &ncf);
    ARKStepGetNumLinSolvSetups(s->mem, &setups);
    ARKStepGetLastStep(s->mem, &hl);
    ARKStepGetCurrentStep(s->mem, &hc);
    st->steps = s->steps0 + steps;
    st->rejected = s->rejected0 + etf + ncf;
    st->setups = s->setups0 + setups;
    st->h_last = hl;
    st->h_next = hc;
}

/* What the library looks up (TSI_ESDIRK_MODULE_SYMBOL). */
__attribute__((visibility("default"))) const tsi_esdirk_module
    towstab_sundials_module = {
        {TSI_ESDIRK_MODULE_VERSION, TSI_MODULE_RELEASE},
        stepper_alloc_method, stepper_free, stepper_reset, stepper_step,
        stepper_interpolate, stepper_get_stats};
