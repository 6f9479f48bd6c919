/* options.c: the option tables of the analyses and option sets
 * (towstab/options.h).
 *
 * One row per option, shared rows (the setup every analysis has, the
 * simulation's settings a convergence study of a simulation takes) written
 * once as macros. A value is parsed by its row only: quantities through
 * udunits2 (towstab/units.h, the scene's parser), plain and whole numbers
 * with strtod/strtol consuming the whole text, names against the row's
 * choices; then the row's limits. An option set keeps, per row and
 * source priority, the texts and where they came from; applying it takes
 * for each row the texts of its highest priority.
 *
 * One module although long: most of its lines are the tables themselves,
 * one row per option, which must stay side by side so that names, limits
 * and defaults are defined once.
 */
#include "towstab/options.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* Texts one source may give a repeatable option. */
#define MAX_TEXTS 32
/* Characters of a `where`. */
#define WHERE_MAX 600

#define OFF(m) offsetof(ts_request, m)
#define SZ(m) sizeof(((ts_request *)0)->m)

/* ---- choices ----------------------------------------------------------- */

static const char *const eq_methods[] = {"auto", "shooting", "newton", NULL};
static const int eq_method_values[] = {TS_EQ_AUTO, TS_EQ_SHOOTING,
                                       TS_EQ_NEWTON};
static const char *const eig_methods[] = {"auto", "lapack", "arpack", NULL};
static const int eig_method_values[] = {TS_EIG_AUTO, TS_EIG_LAPACK,
                                        TS_EIG_ARPACK};
static const char *const integrators[] = {"rk8pd", "rkf45", "rk4imp",
                                          "bsimp", "msbdf", "esdirk", "bdf",
                                          NULL};
static const int integrator_values[] = {TS_INT_RK8PD, TS_INT_RKF45,
                                        TS_INT_RK4IMP, TS_INT_BSIMP,
                                        TS_INT_MSBDF, TS_INT_ESDIRK,
                                        TS_INT_BDF};
static const char *const linear_methods[] = {"expm", "ode", "sparse", NULL};
static const int linear_method_values[] = {TS_LINSIM_EXPM, TS_LINSIM_ODE,
                                           TS_LINSIM_SPARSE};
static const char *const kinematics[] = {"linear", "nonlinear", NULL};
static const int kinematics_values[] = {TS_KIN_LINEAR, TS_KIN_NONLINEAR};
static const char *const studies[] = {"equilibrium", "modes", "simulate",
                                      NULL};
static const int study_values[] = {TS_ANALYSIS_EQUILIBRIUM, TS_ANALYSIS_MODES,
                                   TS_ANALYSIS_SIMULATE};

/* ---- custom parsers ----------------------------------------------------- */

static int parse_initial(const ts_option *o, ts_request *rq, const char *v,
                         const char *w, const ts_units *u, ts_err *err)
{
    (void)o;
    ts_simulate_opts *s = &rq->simulate;
    if (!strcmp(v, "equilibrium")) {
        s->initial = TS_INITIAL_EQUILIBRIUM;
        return TS_OK;
    }
    if (!strncmp(v, "shape:", 6)) {
        if (!v[6])
            return ts_fail(err, TS_EINVAL, "%s: shape: needs a file name", w);
        if (strlen(v + 6) >= sizeof s->shape_file)
            return ts_fail(err, TS_EINVAL, "%s: shape: the file name is "
                           "longer than %zu characters", w,
                           sizeof s->shape_file - 1);
        s->initial = TS_INITIAL_SHAPE;
        snprintf(s->shape_file, sizeof s->shape_file, "%s", v + 6);
        return TS_OK;
    }
    if (strncmp(v, "released", 8) || (v[8] != '\0' && v[8] != ':'))
        return ts_fail(err, TS_EINVAL, "%s: '%s' is not an initial state; "
                       "expected equilibrium, released[:theta1=A,theta2=B] "
                       "or shape:FILE", w, v);
    double th[2] = {0.0, 0.0};
    char buf[256];
    snprintf(buf, sizeof buf, "%s", v[8] ? v + 9 : "");
    char *save = NULL;
    for (char *p = strtok_r(buf, ",", &save); p;
         p = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(p, '=');
        if (eq)
            *eq = '\0';
        int k = !strcmp(p, "theta1") ? 0 : !strcmp(p, "theta2") ? 1 : -1;
        if (!eq || k < 0)
            return ts_fail(err, TS_EINVAL, "%s: released: expected theta1= "
                           "and/or theta2= (angles), got '%s'", w, p);
        char where[WHERE_MAX + 32];
        snprintf(where, sizeof where, "%s: released: %s", w, p);
        int rc = ts_units_parse(u, eq + 1, "rad", where, &th[k], err);
        if (rc)
            return rc;
    }
    s->initial = TS_INITIAL_RELEASED;
    s->theta1 = th[0];
    s->theta2 = th[1];
    return TS_OK;
}

/* The sea state of a response or a simulation: the row's offset is its
 * ts_sea_opts. A file that cannot be read is bad input, like a missing
 * scene (TS_EINVAL, not TS_EIO). */
static ts_sea_opts *sea_opts(const ts_option *o, ts_request *rq)
{
    return (ts_sea_opts *)((char *)rq + o->offset);
}

static int unreadable_is_bad_input(int rc, ts_err *err)
{
    if (rc == TS_EIO) {
        if (err)
            err->code = TS_EINVAL;
        return TS_EINVAL;
    }
    return rc;
}

static int parse_sea(const ts_option *o, ts_request *rq, const char *text,
                     const char *w, const ts_units *u, ts_err *err)
{
    ts_sea *sea = ts_sea_parse(text, u, w, err);
    if (!sea)
        return unreadable_is_bad_input(err && err->code ? err->code
                                                        : TS_EINVAL,
                                       err);
    ts_sea_opts *so = sea_opts(o, rq);
    ts_sea_free(so->sea);
    so->sea = sea;
    return TS_OK;
}

static int parse_rao(const ts_option *o, ts_request *rq, const char *text,
                     const char *w, const ts_units *u, ts_err *err)
{
    ts_sea_opts *so = sea_opts(o, rq);
    if (strlen(text) >= sizeof so->rao_file)
        return ts_fail(err, TS_EINVAL, "%s: the file name is longer than %zu "
                       "characters", w, sizeof so->rao_file - 1);
    ts_rao *rao = ts_rao_read_csv(text, u, err);
    if (!rao) {
        ts_err_prefix(err, "%s: ", w);
        return unreadable_is_bad_input(err && err->code ? err->code
                                                        : TS_EINVAL,
                                       err);
    }
    ts_rao_free(so->rao);
    so->rao = rao;
    snprintf(so->rao_file, sizeof so->rao_file, "%s", text);
    return TS_OK;
}

/* "x,y,z": three lengths. */
static int parse_reference(const ts_option *o, ts_request *rq,
                           const char *text, const char *w,
                           const ts_units *u, ts_err *err)
{
    char buf[256];
    if (strlen(text) >= sizeof buf)
        return ts_fail(err, TS_EINVAL, "%s: too long", w);
    strcpy(buf, text);
    double v[3];
    int n = 0;
    char *save = NULL;
    for (char *tok = strtok_r(buf, ",", &save); tok;
         tok = strtok_r(NULL, ",", &save)) {
        if (n == 3)
            return ts_fail(err, TS_EINVAL, "%s: expected three lengths "
                           "x,y,z (m, in M: x forward, y starboard, z "
                           "down), got '%s'", w, text);
        char where[WHERE_MAX + 8];
        snprintf(where, sizeof where, "%s: %c", w, "xyz"[n]);
        int rc = ts_units_parse(u, tok, "m", where, &v[n], err);
        if (rc)
            return rc;
        n++;
    }
    if (n != 3)
        return ts_fail(err, TS_EINVAL, "%s: expected three lengths x,y,z "
                       "(m, in M: x forward, y starboard, z down), got '%s'",
                       w, text);
    memcpy(sea_opts(o, rq)->reference, v, sizeof v);
    return TS_OK;
}

/* A sweep: links, tolerances or steps of a convergence study. */
static int parse_sweep(const ts_option *o, ts_request *rq, const char *text,
                       const char *w, const ts_units *u, ts_err *err)
{
    (void)u;
    ts_converge_opts *c = &rq->converge;
    ts_conv_param p = !strcmp(o->name, "links")        ? TS_CONV_LINKS
                      : !strcmp(o->name, "tolerances") ? TS_CONV_TOLERANCE
                                                       : TS_CONV_STEP;
    char buf[2048];
    if (strlen(text) >= sizeof buf)
        return ts_fail(err, TS_EINVAL, "%s: list too long", w);
    strcpy(buf, text);
    int n = 0;
    for (char *tok = buf, *next; tok; tok = next) {
        next = strchr(tok, ',');
        if (next)
            *next++ = '\0';
        while (*tok == ' ')
            tok++;
        char *end;
        double v = strtod(tok, &end);
        while (*end == ' ')
            end++;
        if (end == tok || *end || n == TS_CONV_MAX_SETTINGS)
            return ts_fail(err, TS_EINVAL, "%s: expected 1 to %d "
                           "comma-separated numbers like '5,10,20', got "
                           "'%s'", w, TS_CONV_MAX_SETTINGS, text);
        c->settings[n++] = v;
    }
    int rc = ts_conv_check_settings(p, c->settings, n, w, err);
    if (rc)
        return rc;
    c->param = p;
    c->nsettings = n;
    return TS_OK;
}

/* "x1,y1;x2,y2;...": lengths, each with its unit or in metres. */
static int parse_waypoints(const ts_option *o, ts_request *rq,
                           const char *text, const char *w,
                           const ts_units *u, ts_err *err)
{
    (void)o;
    ts_simulate_opts *s = &rq->simulate;
    char buf[2048];
    if (strlen(text) >= sizeof buf)
        return ts_fail(err, TS_EINVAL, "%s: list too long", w);
    strcpy(buf, text);
    double xy[TS_GUIDANCE_MAX_WAYPOINTS][2];
    int n = 0;
    /* Split at every ';' and ',' (an empty item is an error, unlike
     * strtok). */
    for (char *pt = buf, *next; pt; pt = next, n++) {
        next = strchr(pt, ';');
        if (next)
            *next++ = '\0';
        char *y = strchr(pt, ',');
        if (n == TS_GUIDANCE_MAX_WAYPOINTS || !y || strchr(y + 1, ','))
            return ts_fail(err, TS_EINVAL, "%s: expected 1 to %d waypoints "
                           "'x1,y1;x2,y2;...' (lengths, e.g. "
                           "'100 m,0 m;200 m,50 m'), got '%s'", w,
                           TS_GUIDANCE_MAX_WAYPOINTS, text);
        *y++ = '\0';
        const char *xyz[2] = {pt, y};
        for (int j = 0; j < 2; j++) {
            char where[WHERE_MAX + 48];
            snprintf(where, sizeof where, "%s: waypoint %d %c", w, n + 1,
                     "xy"[j]);
            int rc = ts_units_parse(u, xyz[j], "m", where, &xy[n][j], err);
            if (rc)
                return rc;
        }
    }
    s->nwaypoints = n;
    memcpy(s->waypoints, xy, (size_t)n * sizeof xy[0]);
    return TS_OK;
}

static int parse_integrators(const ts_option *o, ts_request *rq,
                             const char *text, const char *w,
                             const ts_units *u, ts_err *err)
{
    (void)o;
    (void)u;
    ts_converge_opts *c = &rq->converge;
    char buf[256];
    if (strlen(text) >= sizeof buf)
        return ts_fail(err, TS_EINVAL, "%s: list too long", w);
    strcpy(buf, text);
    int n = 0;
    char *save = NULL;
    for (char *tok = strtok_r(buf, ", ", &save); tok;
         tok = strtok_r(NULL, ", ", &save)) {
        ts_integrator m;
        if (ts_integrator_parse(tok, &m) != 0)
            return ts_fail(err, TS_EINVAL, "%s: '%s' is not an integrator; "
                           "expected rk8pd, rkf45, rk4imp, bsimp, msbdf, "
                           "esdirk or bdf", w, tok);
        for (int i = 0; i < n; i++)
            if (c->integrators[i] == m)
                return ts_fail(err, TS_EINVAL, "%s: %s is given twice", w,
                               tok);
        if (n == TS_CONVERGE_MAX_SERIES)
            return ts_fail(err, TS_EINVAL, "%s: at most %d integrators", w,
                           TS_CONVERGE_MAX_SERIES);
        c->integrators[n++] = m;
    }
    if (n == 0)
        return ts_fail(err, TS_EINVAL, "%s: expected integrators like "
                       "'rk8pd,rkf45', got '%s'", w, text);
    c->nintegrators = n;
    return TS_OK;
}

/* Scene values by path: "PATH=VALUE", several separated by ';' (a
 * repeated --set adds more). The value has the path's unit
 * (towstab/param.h); a loop's gains and setpoint, whose unit depends on
 * what the loop measures, are a plain SI number or a value in the unit of
 * a depth or an angle loop, checked against the loop with the system
 * (ts_param_parse, ts_param_fits). */
static int parse_set(const ts_option *o, ts_request *rq, const char *text,
                     const char *w, const ts_units *u, ts_err *err)
{
    (void)o;
    char *copy = strdup(text);
    if (!copy)
        return ts_fail(err, TS_ENOMEM, "%s: out of memory", w);
    int rc = TS_OK;
    char *save = NULL;
    int n = 0;
    for (char *p = strtok_r(copy, ";", &save); p && !rc;
         p = strtok_r(NULL, ";", &save)) {
        while (*p == ' ')
            p++;
        char *eq = strchr(p, '=');
        if (!eq) {
            if (!*p)
                continue;
            rc = ts_fail(err, TS_EINVAL, "%s: expected PATH=VALUE (e.g. "
                         "cables.main.length=120m), got '%s'", w, p);
            break;
        }
        char *end = eq;
        while (end > p && end[-1] == ' ')
            end--;
        *end = '\0';
        const char *val = eq + 1;
        while (*val == ' ')
            val++;
        char own[TS_PARAM_UNIT_MAX], unit[TS_PARAM_UNIT_MAX];
        char where[WHERE_MAX + TS_PARAM_PATH_MAX];
        snprintf(where, sizeof where, "%s: %s", w, p);
        rc = ts_param_unit(NULL, p, own, sizeof own, err);
        if (rc) {
            ts_err_prefix(err, "%s: ", w);
            break;
        }
        double v;
        rc = ts_param_parse(NULL, u, p, val, where, &v, unit, sizeof unit,
                            err);
        if (!rc)
            rc = ts_setup_set_in(&rq->setup, p, v, own[0] ? "" : unit, val,
                                 err);
        n++;
    }
    free(copy);
    if (!rc && n == 0)
        rc = ts_fail(err, TS_EINVAL, "%s: expected PATH=VALUE, got '%s'", w,
                     text);
    return rc;
}

/* ---- the tables ---------------------------------------------------------- */

/* Rows by field name; what a row leaves out is 0 or NULL. Limits NAN:
 * none (set explicitly: a zero limit is a limit). */
#define NOLIM .min = NAN, .max = NAN

/* The setup every analysis shares; `links` apart (a study sweeps it). */
#define SETUP_ROWS                                                            \
    {.name = "speed", .type = TS_OPT_QUANTITY, .section = TS_SEC_SETUP,       \
     .unit = "m/s", .min = 0, .max = INFINITY, .offset = OFF(setup.speed),    \
     .arg = "Q", .help = "tow speed, e.g. '5 knot'",                          \
     .deftext = "the scene's tow.speed"},                                     \
    {.name = "turn_rate", .type = TS_OPT_QUANTITY, .section = TS_SEC_SETUP,   \
     .unit = "rad/s", .min = -INFINITY, .max = INFINITY,                      \
     .offset = OFF(setup.turn_rate), .arg = "Q",                              \
     .help = "turn rate, > 0 starboard, e.g. '0.5 rad/s'",                    \
     .deftext = "the scene's tow.turn_rate"},                                 \
    {.name = "equilibrium_method", .type = TS_OPT_ENUM,                       \
     .section = TS_SEC_SETUP, NOLIM, .choices = eq_methods,                   \
     .values = eq_method_values, .offset = OFF(setup.equilibrium.method),     \
     .arg = "M", .help = "the equilibrium's solver"},                         \
    {.name = "tolerance", .type = TS_OPT_NUMBER, .section = TS_SEC_SETUP,     \
     .min = 0, .max = 1, .flags = TS_OPT_MIN_OPEN | TS_OPT_MAX_OPEN,          \
     .offset = OFF(setup.equilibrium.tol), .arg = "X",                        \
     .help = "the equilibrium's relative force residual"},                    \
    {.name = "set", .type = TS_OPT_CUSTOM, .section = TS_SEC_SETUP, NOLIM,    \
     .flags = TS_OPT_REPEAT, .offset = OFF(setup.sets), .parse = parse_set,   \
     .arg = "PATH=Q",                                                         \
     .help = "a scene value by its path, e.g. cables.main.length=120m "       \
             "(';' separates several)",                                       \
     .deftext = "none"}
#define OPEN_LOOP_ROW                                                         \
    {.name = "open_loop", .type = TS_OPT_BOOL, .section = TS_SEC_SETUP,       \
     NOLIM, .offset = OFF(setup.open_loop),                                   \
     .help = "the vehicles' controller loops open about the closed-loop "    \
             "trim (the plant a controller is designed against)"}
#define LINKS_ROW                                                             \
    {.name = "links", .type = TS_OPT_INT, .section = TS_SEC_SETUP, .min = 1,  \
     .max = TS_MAX_LINKS, .offset = OFF(setup.links), .arg = "N",             \
     .help = "equal links on every cable", .deftext = "the scene's links"}

/* How accurate a result must be, and whether it is checked. */
#define ACCURACY_ROWS                                                         \
    {.name = "accuracy", .type = TS_OPT_NUMBER, .section = TS_SEC_SETUP,      \
     .min = 0, .max = 1, .flags = TS_OPT_MIN_OPEN | TS_OPT_MAX_OPEN,          \
     .offset = OFF(setup.accuracy), .arg = "X",                               \
     .help = "relative discretisation error allowed of the key values; "      \
             "missed: not trustworthy"},                                      \
    {.name = "discretisation_error", .type = TS_OPT_BOOL,                     \
     .section = TS_SEC_SETUP, NOLIM,                                          \
     .offset = OFF(setup.discretisation_error),                               \
     .help = "estimate it from the same analysis at about half (and a "       \
             "quarter of) the links"},                                        \
    {.name = "refine", .type = TS_OPT_BOOL, .section = TS_SEC_SETUP, NOLIM,   \
     .offset = OFF(setup.refine),                                             \
     .help = "rerun with the links the error model says meet the "            \
             "accuracy (equal links)"}

/* The settings of a simulation; `only` for a convergence study. */
#define SIM_ROWS(o)                                                           \
    {.name = "t_end", .type = TS_OPT_QUANTITY, .section = TS_SEC_SIMULATE,    \
     .unit = "s", .min = 0, .max = INFINITY, .flags = TS_OPT_MIN_OPEN,        \
     .offset = OFF(simulate.sim.t_end), .only = o, .arg = "T",                \
     .help = "run length"},                                                   \
    {.name = "sample", .type = TS_OPT_QUANTITY, .section = TS_SEC_SIMULATE,   \
     .unit = "s", .min = 0, .max = INFINITY,                                  \
     .flags = TS_OPT_MIN_OPEN | TS_OPT_YIELD,                                 \
     .offset = OFF(simulate.sim.dt_sample), .only = o, .arg = "DT",           \
     .help = "output interval",                                               \
     .deftext = "0.05 s, at most 1/16 of a periodic excitation's period"},    \
    {.name = "initial", .type = TS_OPT_CUSTOM, .section = TS_SEC_SIMULATE,    \
     NOLIM, .offset = OFF(simulate.initial), .only = o,                       \
     .parse = parse_initial, .arg = "S",                                      \
     .help = "equilibrium, released[:theta1=A,theta2=B] (straight, at "       \
             "rest) or shape:FILE (node,x_m,y_m,z_m)",                        \
     .deftext = "equilibrium"},                                               \
    {.name = "integrator", .type = TS_OPT_ENUM, .section = TS_SEC_SIMULATE,   \
     NOLIM, .choices = integrators, .values = integrator_values,              \
     .offset = OFF(simulate.sim.integrator), .only = o, .arg = "M",           \
     .help = "the nonlinear integrator (esdirk for stiff elastic cables)"},   \
    {.name = "rtol", .type = TS_OPT_NUMBER, .section = TS_SEC_SIMULATE,       \
     .min = TS_SIM_RTOL_MIN, .max = 1, .flags = TS_OPT_MAX_OPEN,              \
     .offset = OFF(simulate.sim.rel_tol), .only = o, .arg = "X",              \
     .help = "the integrator's relative tolerance"},                          \
    {.name = "atol", .type = TS_OPT_NUMBER, .section = TS_SEC_SIMULATE,       \
     .min = 0, .max = 1, .flags = TS_OPT_MIN_OPEN | TS_OPT_MAX_OPEN,          \
     .offset = OFF(simulate.sim.abs_tol), .only = o, .arg = "X",              \
     .help = "the integrator's absolute tolerance (rad, rad/s)"},             \
    {.name = "h_min", .type = TS_OPT_QUANTITY, .section = TS_SEC_SIMULATE,    \
     .unit = "s", .min = 0, .max = INFINITY,                                  \
     .offset = OFF(simulate.sim.h_min), .only = o, .arg = "T",                \
     .help = "fail when the step falls below this"},                          \
    {.name = "max_steps", .type = TS_OPT_LONG, .section = TS_SEC_SIMULATE,    \
     .min = 1, .max = 1e15, .offset = OFF(simulate.sim.max_steps),            \
     .only = o, .arg = "N", .help = "fail after this many steps",             \
     .deftext = "no limit"},                                                  \
    {.name = "transient", .type = TS_OPT_QUANTITY,                            \
     .section = TS_SEC_SIMULATE, .unit = "s", .min = 0, .max = INFINITY,      \
     .flags = TS_OPT_YIELD, .offset = OFF(simulate.transient), .only = o,     \
     .arg = "T", .help = "time discarded before comparing or fitting",        \
     .deftext = "t_end / 2"},                                                 \
    {.name = "output", .type = TS_OPT_TEXT, .section = TS_SEC_SIMULATE,       \
     NOLIM, .offset = OFF(simulate.output), .size = SZ(simulate.output),      \
     .only = o, .arg = "NAME",                                                \
     .help = "the channel compared and fitted, e.g. sphere.z, "               \
             "cable.3.tension, tow.force, fish.depth",                        \
     .deftext = "the last sphere's .z"},                                      \
    {.name = "linear_method", .type = TS_OPT_ENUM,                            \
     .section = TS_SEC_SIMULATE, NOLIM, .choices = linear_methods,            \
     .values = linear_method_values,                                          \
     .offset = OFF(simulate.sim.linear_method), .only = o, .arg = "M",        \
     .help = "the linear model's integration; sparse: esdirk on the "      \
             "sparse model (any method above 1200 states)"},                  \
    {.name = "kinematics", .type = TS_OPT_ENUM, .section = TS_SEC_SIMULATE,   \
     NOLIM, .choices = kinematics, .values = kinematics_values,               \
     .offset = OFF(simulate.sim.kinematics), .only = o, .arg = "K",           \
     .help = "positions of the linear run"},                                  \
    {.name = "excite", .type = TS_OPT_SPECS, .section = TS_SEC_SIMULATE,      \
     NOLIM, .flags = TS_OPT_REPEAT, .offset = OFF(simulate.excitation),       \
     .only = o, .arg = "SPEC",                                                \
     .help = "tow-point (tow.surge, tow.sway, tow.heave), ship rotation "    \
             "(tow.roll, tow.pitch, tow.yaw) or vehicle-input excitation, "  \
             "e.g. tow.heave:amplitude=0.1ft,frequency=1Hz or "               \
             "fish.depth.setpoint:step,amplitude=5m",                         \
     .deftext = "none"},                                                      \
    {.name = "manoeuvre", .type = TS_OPT_SPECS, .section = TS_SEC_SIMULATE,   \
     NOLIM, .flags = TS_OPT_REPEAT, .offset = OFF(simulate.excitation),       \
     .only = o, .arg = "SPEC",                                                \
     .help = "speed or turn_rate ramp or step, e.g. "                         \
             "turn_rate:to=0.5rad/s,duration=1s",                             \
     .deftext = "none"},                                                      \
    {.name = "compare", .type = TS_OPT_BOOL, .section = TS_SEC_SIMULATE,      \
     NOLIM, .offset = OFF(simulate.compare), .group = 2, .only = o,           \
     .help = "run the linear and the nonlinear model and compare them"},      \
    {.name = "linear", .type = TS_OPT_BOOL, .section = TS_SEC_SIMULATE,       \
     NOLIM, .offset = OFF(simulate.linear), .group = 2, .only = o,            \
     .help = "run the linear model only"}

/* The sea state of a response or a simulation (section `sec`, the
 * ts_sea_opts at `field`). */
#define SEA_ROWS(sec, field)                                                  \
    {.name = "sea", .type = TS_OPT_CUSTOM, .section = sec, NOLIM,             \
     .offset = OFF(field), .parse = parse_sea, .arg = "SPEC",                 \
     .help = "irregular sea: Hs=4m,Tp=10s[,gamma=3.3][,heading=150deg], "     \
             "type=pm,Hs=..,Tp=.. or file=SPECTRUM.csv",                      \
     .deftext = "none"},                                                      \
    {.name = "rao", .type = TS_OPT_CUSTOM, .section = sec, NOLIM,             \
     .offset = OFF(field), .parse = parse_rao, .arg = "FILE",                 \
     .help = "the ship's RAOs (CSV, doc/seastate.md)",                        \
     .deftext = "none: the tow point follows the water surface"},             \
    {.name = "rao_reference", .type = TS_OPT_CUSTOM, .section = sec, NOLIM,   \
     .offset = OFF(field), .parse = parse_reference, .arg = "X,Y,Z",          \
     .help = "the RAOs' reference point in M (the lever arm is the tow "      \
             "point less it; with a towing vehicle its rotations turn "       \
             "each cable's start about the vehicle's origin)",               \
     .deftext = "0,0,0 m (M's origin)"}

static const ts_option eq_rows[] = {SETUP_ROWS, LINKS_ROW, ACCURACY_ROWS};

static const ts_option modes_rows[] = {
    SETUP_ROWS,
    LINKS_ROW,
    ACCURACY_ROWS,
    {.name = "count", .type = TS_OPT_INT, .section = TS_SEC_MODES, .min = 1,
     .max = 100000000, .offset = OFF(modes.count), .arg = "N",
     .help = "modes to report",
     .deftext = "all; 20 from 1200 states on; 10 with near"},
    {.name = "near", .type = TS_OPT_QUANTITY, .section = TS_SEC_MODES,
     .unit = "Hz", .min = 0, .max = INFINITY,
     .offset = OFF(modes.eigen.target_hz), .flag_offset = OFF(modes.near),
     .arg = "F", .help = "the modes nearest this frequency",
     .deftext = "the lowest modes"},
    {.name = "eigen_method", .type = TS_OPT_ENUM, .section = TS_SEC_MODES,
     NOLIM, .choices = eig_methods, .values = eig_method_values,
     .offset = OFF(modes.eigen.method), .arg = "M",
     .help = "lapack: every eigenvalue; arpack: shift-invert, a subset"},
    OPEN_LOOP_ROW,
    {.name = "margins", .type = TS_OPT_BOOL, .section = TS_SEC_MODES, NOLIM,
     .offset = OFF(modes.margins),
     .help = "with controller loops: each loop's gain and phase margins, "
             "broken one at a time"},
    {.name = "free_vehicle", .type = TS_OPT_BOOL, .section = TS_SEC_MODES,
     NOLIM, .offset = OFF(modes.free_vehicle),
     .help = "with a towing vehicle: its own modes alone, without the cable, "
             "at the same speed, each matched to the coupled mode of the "
             "same shape"},
    {.name = "oscillatory", .type = TS_OPT_BOOL, .section = TS_SEC_MODES,
     NOLIM, .offset = OFF(modes.oscillatory),
     .help = "list the oscillatory modes only (they come first anyway)"},
};

static const ts_option response_rows[] = {
    SETUP_ROWS,
    LINKS_ROW,
    ACCURACY_ROWS,
    {.name = "input", .type = TS_OPT_TEXT, .section = TS_SEC_RESPONSE, NOLIM,
     .offset = OFF(response.input), .size = SZ(response.input),
     .flag_offset = OFF(response.frequency_given), .arg = "NAME",
     .help = "tow.surge, tow.sway or tow.heave, tow.roll, tow.pitch or "
             "tow.yaw (a small rotation of the ship), tow.speed or "
             "tow.turn_rate, or a vehicle's input: <vehicle>.<surface>, "
             "<vehicle>.<loop>, <vehicle>.<loop>.setpoint; a towing "
             "vehicle's <name>.thrust, .force.x|y|z, .moment.x|y|z, "
             ".speed_set (a speed controller's)"},
    {.name = "output", .type = TS_OPT_TEXT, .section = TS_SEC_RESPONSE, NOLIM,
     .offset = OFF(response.output), .size = SZ(response.output),
     .arg = "NAME",
     .help = "<node>.x, .y or .z (sphere.z, cable.3.x), "
             "<cable>.<k>.tension, or a vehicle's <vehicle>.depth, .pitch, "
             ".roll, .yaw, .<loop>.output or .<surface>.deflection",
     .deftext = "required"},
    {.name = "from", .type = TS_OPT_QUANTITY, .section = TS_SEC_RESPONSE,
     .unit = "Hz", .min = 0, .max = INFINITY, .flags = TS_OPT_MIN_OPEN,
     .offset = OFF(response.from_hz),
     .flag_offset = OFF(response.frequency_given), .arg = "F",
     .help = "lowest frequency"},
    {.name = "to", .type = TS_OPT_QUANTITY, .section = TS_SEC_RESPONSE,
     .unit = "Hz", .min = 0, .max = INFINITY, .flags = TS_OPT_MIN_OPEN,
     .offset = OFF(response.to_hz),
     .flag_offset = OFF(response.frequency_given), .arg = "F",
     .help = "highest frequency"},
    {.name = "points", .type = TS_OPT_INT, .section = TS_SEC_RESPONSE,
     .min = 2, .max = TS_RESPONSE_MAX_POINTS, .offset = OFF(response.points),
     .flag_offset = OFF(response.frequency_given), .arg = "N",
     .help = "log-spaced frequencies"},
    OPEN_LOOP_ROW,
    SEA_ROWS(TS_SEC_RESPONSE, response.sea),
    {.name = "intervals", .type = TS_OPT_INT, .section = TS_SEC_RESPONSE,
     .min = 16, .max = 1 << 20, .offset = OFF(response.intervals),
     .arg = "N", .help = "with sea: intervals of the spectral grid, a "
                         "multiple of 8"},
    {.name = "duration", .type = TS_OPT_QUANTITY, .section = TS_SEC_RESPONSE,
     .unit = "s", .min = 0, .max = INFINITY, .flags = TS_OPT_MIN_OPEN,
     .offset = OFF(response.duration), .arg = "T",
     .help = "with sea: the duration of the most probable maximum"},
};

static const ts_option simulate_rows[] = {
    SETUP_ROWS,
    LINKS_ROW,
    ACCURACY_ROWS,
    SIM_ROWS(0),
    OPEN_LOOP_ROW,
    SEA_ROWS(TS_SEC_SIMULATE, simulate.sea),
    {.name = "seed", .type = TS_OPT_LONG, .section = TS_SEC_SIMULATE,
     .min = 0, .max = 4294967295.0, .offset = OFF(simulate.seed), .arg = "N",
     .help = "the sea realisation's random seed"},
    {.name = "components", .type = TS_OPT_INT, .section = TS_SEC_SIMULATE,
     .min = 1, .max = 1000000, .offset = OFF(simulate.components),
     .arg = "N", .help = "sinusoids of the sea realisation"},
    {.name = "fade_in", .type = TS_OPT_QUANTITY, .section = TS_SEC_SIMULATE,
     .unit = "s", .min = 0, .max = INFINITY,
     .offset = OFF(simulate.fade_in), .arg = "T",
     .help = "the sea's fade-in from rest", .deftext = "2 Tp"},
    {.name = "waypoints", .type = TS_OPT_CUSTOM, .section = TS_SEC_SIMULATE,
     NOLIM, .offset = OFF(simulate.nwaypoints), .parse = parse_waypoints,
     .arg = "LIST",
     .help = "waypoints x1,y1;x2,y2;... (earth frame, lengths) in place "
             "of the points of the scene's waypoints entry",
     .deftext = "the scene's"},
    {.name = "outputs", .type = TS_OPT_TEXT, .section = TS_SEC_SIMULATE,
     NOLIM, .offset = OFF(simulate.outputs), .size = SZ(simulate.outputs),
     .arg = "LIST",
     .help = "the channels written and printed, e.g. "
             "fish.z,armour.1.tension,tow.force,fish.pitch,"
             "fish.tail1.deflection; all: the full state",
     .deftext = "the output (a node's x, y, z) and tow.force"},
};

static const ts_option converge_rows[] = {
    {.name = "analysis", .type = TS_OPT_ENUM, .section = TS_SEC_CONVERGE,
     NOLIM, .choices = studies, .values = study_values,
     .offset = OFF(converge.analysis), .arg = "A",
     .help = "the analysis rerun"},
    {.name = "links", .type = TS_OPT_LIST, .section = TS_SEC_CONVERGE, NOLIM,
     .offset = OFF(converge.settings), .group = 1, .parse = parse_sweep,
     .arg = "LIST", .help = "links per cable to sweep, e.g. 5,10,20,40",
     .deftext = "5,10,20,40,80,160,320; modes 10,20,40,80"},
    {.name = "tolerances", .type = TS_OPT_LIST, .section = TS_SEC_CONVERGE,
     NOLIM, .offset = OFF(converge.settings), .group = 1,
     .parse = parse_sweep, .arg = "LIST",
     .help = "tolerances to sweep: the equilibrium's residual, or the "
             "integrator's (simulate)",
     .deftext = "simulate 1e-3,1e-5,1e-7,1e-9"},
    {.name = "steps", .type = TS_OPT_LIST, .section = TS_SEC_CONVERGE, NOLIM,
     .offset = OFF(converge.settings), .group = 1,
     .only = TS_ANALYSIS_MODES + 1, .parse = parse_sweep, .arg = "LIST",
     .help = "relative linearization steps to sweep", .deftext = "none"},
    {.name = "target", .type = TS_OPT_NUMBER, .section = TS_SEC_CONVERGE,
     .min = 0, .max = 1, .flags = TS_OPT_MIN_OPEN | TS_OPT_MAX_OPEN,
     .offset = OFF(converge.target), .arg = "X",
     .help = "relative error wanted"},
    {.name = "modes", .type = TS_OPT_INT, .section = TS_SEC_MODES, .min = 1,
     .max = 100, .offset = OFF(modes.follow), .only = TS_ANALYSIS_MODES + 1,
     .arg = "K", .help = "lowest oscillatory modes to follow"},
    {.name = "integrators", .type = TS_OPT_LIST, .section = TS_SEC_CONVERGE,
     NOLIM, .offset = OFF(converge.integrators),
     .only = TS_ANALYSIS_SIMULATE + 1, .parse = parse_integrators,
     .arg = "LIST", .help = "one series per integrator, e.g. rk8pd,msbdf",
     .deftext = "the simulation's integrator"},
    SETUP_ROWS,
    OPEN_LOOP_ROW,
    SIM_ROWS(TS_ANALYSIS_SIMULATE + 1),
};

#define COUNT(a) ((int)(sizeof(a) / sizeof((a)[0])))

const ts_option *ts_options(ts_analysis_kind kind, int *n)
{
    switch (kind) {
    case TS_ANALYSIS_EQUILIBRIUM: *n = COUNT(eq_rows); return eq_rows;
    case TS_ANALYSIS_MODES: *n = COUNT(modes_rows); return modes_rows;
    case TS_ANALYSIS_RESPONSE:
        *n = COUNT(response_rows);
        return response_rows;
    case TS_ANALYSIS_SIMULATE:
        *n = COUNT(simulate_rows);
        return simulate_rows;
    case TS_ANALYSIS_CONVERGE:
        *n = COUNT(converge_rows);
        return converge_rows;
    }
    *n = 0;
    return NULL;
}

void ts_option_cli_name(const ts_option *o, char *buf, size_t size)
{
    snprintf(buf, size, "%s", o->name);
    for (char *p = buf; *p; p++)
        if (*p == '_')
            *p = '-';
}

const ts_option *ts_option_find(ts_analysis_kind kind, const char *name)
{
    int n;
    const ts_option *t = ts_options(kind, &n);
    char cli[TS_NAME_MAX];
    for (int i = 0; name && i < n; i++) {
        ts_option_cli_name(&t[i], cli, sizeof cli);
        if (!strcmp(t[i].name, name) || !strcmp(cli, name))
            return &t[i];
    }
    return NULL;
}

/* ---- one value ----------------------------------------------------------- */

/* "> 0", ">= 1e-14 and < 1", "in [1, 100000]" of a row's limits. */
void ts_option_limits_text(const ts_option *o, char *buf, size_t size)
{
    buf[0] = '\0';
    if (o->choices) {
        size_t len = 0;
        for (int i = 0; o->choices[i]; i++)
            len += (size_t)snprintf(buf + len, len < size ? size - len : 0,
                                    "%s%s", i ? ", " : "", o->choices[i]);
        return;
    }
    int lo = !isnan(o->min) && isfinite(o->min);
    int hi = !isnan(o->max) && isfinite(o->max);
    const char *u = o->type == TS_OPT_QUANTITY && strcmp(o->unit, "1")
                        ? o->unit : "";
    const char *sp = u[0] ? " " : "";
    if (o->type == TS_OPT_INT || o->type == TS_OPT_LONG) {
        if (hi && o->max < 1e15)
            snprintf(buf, size, "%.0f to %.0f", o->min, o->max);
        else
            snprintf(buf, size, ">= %.0f", o->min);
        return;
    }
    if (lo && hi)
        snprintf(buf, size, "%s %g%s%s and %s %g%s%s",
                 o->flags & TS_OPT_MIN_OPEN ? ">" : ">=", o->min, sp, u,
                 o->flags & TS_OPT_MAX_OPEN ? "<" : "<=", o->max, sp, u);
    else if (lo)
        snprintf(buf, size, "%s %g%s%s",
                 o->flags & TS_OPT_MIN_OPEN ? ">" : ">=", o->min, sp, u);
    else if (hi)
        snprintf(buf, size, "%s %g%s%s",
                 o->flags & TS_OPT_MAX_OPEN ? "<" : "<=", o->max, sp, u);
    else if (o->type == TS_OPT_QUANTITY || o->type == TS_OPT_NUMBER)
        snprintf(buf, size, "finite");
}

/* Check a number against the row's limits. */
static int check_limits(const ts_option *o, double v, const char *text,
                        const char *w, ts_err *err)
{
    int bad = !isfinite(v);
    if (!isnan(o->min) && isfinite(o->min))
        bad |= o->flags & TS_OPT_MIN_OPEN ? !(v > o->min) : !(v >= o->min);
    if (!isnan(o->max) && isfinite(o->max))
        bad |= o->flags & TS_OPT_MAX_OPEN ? !(v < o->max) : !(v <= o->max);
    if (!bad)
        return TS_OK;
    char lim[128];
    ts_option_limits_text(o, lim, sizeof lim);
    if (o->type == TS_OPT_QUANTITY && strcmp(o->unit, "1"))
        return ts_fail(err, TS_EINVAL, "%s: must be %s, got %g %s", w, lim,
                       v, o->unit);
    if (o->type == TS_OPT_INT || o->type == TS_OPT_LONG)
        return ts_fail(err, TS_EINVAL, "%s: expected a whole number %s%s, "
                       "got '%s'", w, isfinite(o->max) && o->max < 1e15
                                          ? "from " : "", lim, text);
    return ts_fail(err, TS_EINVAL, "%s: must be %s, got '%s'", w, lim, text);
}

static int parse_choice(const ts_option *o, const char *text, const char *w,
                        int *index, ts_err *err)
{
    for (int i = 0; o->choices[i]; i++)
        if (!strcmp(text, o->choices[i])) {
            *index = i;
            return TS_OK;
        }
    char list[256];
    ts_option_limits_text(o, list, sizeof list);
    return ts_fail(err, TS_EINVAL, "%s: '%s' is not one of %s", w, text,
                   list);
}

/* Add every ';'-separated spec of `text` to the excitation; a manoeuvre
 * row takes manoeuvres only, an excite row tow-point motions only. */
static int add_specs(const ts_option *o, ts_request *rq, const char *text,
                     const char *w, const ts_units *u, ts_err *err)
{
    int manoeuvre = !strcmp(o->name, "manoeuvre");
    ts_simulate_opts *s = &rq->simulate;
    if (!s->excitation && !(s->excitation = ts_excitation_alloc(err)))
        return err && err->code ? err->code : TS_ENOMEM;
    char *copy = strdup(text);
    if (!copy)
        return ts_fail(err, TS_ENOMEM, "%s: out of memory", w);
    int rc = TS_OK, n = 0;
    char *p = copy;
    for (char *next; p && !rc; p = next) {
        next = strchr(p, ';');
        if (next)
            *next++ = '\0';
        while (*p == ' ')
            p++;
        size_t len = strlen(p);
        while (len > 0 && p[len - 1] == ' ')
            p[--len] = '\0';
        if (!len) {
            rc = ts_fail(err, TS_EINVAL, "%s: an empty spec; expected e.g. "
                         "%s", w, manoeuvre
                                      ? "turn_rate:to=0.5rad/s,duration=1s"
                                      : "tow.heave:amplitude=0.1ft,"
                                        "frequency=1Hz");
            break;
        }
        int i = ts_excitation_nsignals(s->excitation);
        rc = ts_excitation_parse(s->excitation, p, u, w, err);
        if (rc == TS_EIO)
            rc = err->code = TS_EINVAL; /* a missing series file is bad
                                           input, like a missing scene */
        if (!rc) {
            const ts_signal *sg = ts_excitation_signal(s->excitation, i);
            int is_man = sg->axis == TS_AXIS_SPEED ||
                         sg->axis == TS_AXIS_TURN_RATE;
            if (is_man != manoeuvre)
                rc = ts_fail(err, TS_EINVAL, "%s: '%s' is %s; give it as %s",
                             w, ts_signal_axis_label(sg),
                             is_man ? "a manoeuvre of the ship"
                                    : "a tow-point or vehicle-input "
                                      "excitation",
                             is_man ? "manoeuvre (--manoeuvre)"
                                    : "excite (--excite)");
            else if (sg->axis == TS_AXIS_SPEED && sg->absolute &&
                     !(sg->amplitude >= 0))
                rc = ts_fail(err, TS_EINVAL, "%s: the speed must stay >= 0 "
                             "m/s (as tow.speed), got to=%g m/s", w,
                             sg->amplitude);
        }
        n++;
    }
    free(copy);
    return rc;
}

int ts_option_set(const ts_option *o, ts_request *rq, const char *text,
                  const char *w, const ts_units *u, ts_err *err)
{
    char *at = (char *)rq + o->offset;
    int rc = TS_OK;
    if (!text)
        return ts_fail(err, TS_EINVAL, "%s: needs a value", w);
    if (o->type != TS_OPT_SPECS && !text[0])
        return ts_fail(err, TS_EINVAL, "%s: needs a value, got an empty one",
                       w);
    switch (o->type) {
    case TS_OPT_QUANTITY: {
        double v;
        rc = ts_units_parse(u, text, o->unit, w, &v, err);
        if (!rc)
            rc = check_limits(o, v, text, w, err);
        if (!rc)
            *(double *)at = v;
        break;
    }
    case TS_OPT_NUMBER: {
        char *end;
        double v = strtod(text, &end);
        if (end == text || *end)
            return ts_fail(err, TS_EINVAL, "%s: expected a number, got '%s'",
                           w, text);
        rc = check_limits(o, v, text, w, err);
        if (!rc)
            *(double *)at = v;
        break;
    }
    case TS_OPT_INT:
    case TS_OPT_LONG: {
        char *end;
        long v = strtol(text, &end, 10);
        if (end == text || *end)
            return check_limits(o, NAN, text, w, err);
        rc = check_limits(o, (double)v, text, w, err);
        if (!rc && o->type == TS_OPT_INT)
            *(int *)at = (int)v;
        else if (!rc)
            *(long *)at = v;
        break;
    }
    case TS_OPT_BOOL:
        if (!strcmp(text, "true") || !strcmp(text, "yes") ||
            !strcmp(text, "1"))
            *(int *)at = 1;
        else if (!strcmp(text, "false") || !strcmp(text, "no") ||
                 !strcmp(text, "0"))
            *(int *)at = 0;
        else
            rc = ts_fail(err, TS_EINVAL, "%s: expected true or false, got "
                         "'%s'", w, text);
        break;
    case TS_OPT_ENUM: {
        int i = 0;
        rc = parse_choice(o, text, w, &i, err);
        if (!rc)
            *(int *)at = o->values ? o->values[i] : i;
        break;
    }
    case TS_OPT_TEXT: {
        int i = 0;
        if (o->choices && (rc = parse_choice(o, text, w, &i, err)))
            break;
        if (strlen(text) >= o->size)
            return ts_fail(err, TS_EINVAL, "%s: longer than %zu characters",
                           w, o->size - 1);
        snprintf(at, o->size, "%s", text);
        break;
    }
    case TS_OPT_SPECS:
        rc = add_specs(o, rq, text, w, u, err);
        break;
    case TS_OPT_LIST:
    case TS_OPT_CUSTOM:
        rc = o->parse(o, rq, text, w, u, err);
        break;
    }
    if (!rc && o->flag_offset)
        *(int *)((char *)rq + o->flag_offset) = 1;
    return rc;
}

void ts_option_default_text(const ts_option *o, ts_analysis_kind kind,
                            char *buf, size_t size)
{
    if (o->deftext) {
        snprintf(buf, size, "%s", o->deftext);
        return;
    }
    ts_request rq;
    ts_request_init(&rq, kind);
    const char *at = (const char *)&rq + o->offset;
    buf[0] = '\0';
    switch (o->type) {
    case TS_OPT_QUANTITY:
    case TS_OPT_NUMBER: {
        double v = *(const double *)at;
        if (isnan(v) || (v == 0 && o->flags & TS_OPT_MIN_OPEN))
            return; /* "the scene's", or a rule */
        if (o->type == TS_OPT_QUANTITY && strcmp(o->unit, "1"))
            snprintf(buf, size, "%g %s", v, o->unit);
        else
            snprintf(buf, size, "%g", v);
        break;
    }
    case TS_OPT_INT:
    case TS_OPT_LONG: {
        long v = o->type == TS_OPT_INT ? *(const int *)at
                                       : *(const long *)at;
        if (v != 0)
            snprintf(buf, size, "%ld", v);
        break;
    }
    case TS_OPT_BOOL: snprintf(buf, size, "%s", *(const int *)at ? "true"
                                                                 : "false");
        break;
    case TS_OPT_ENUM: {
        int v = *(const int *)at;
        for (int i = 0; o->choices[i]; i++)
            if ((o->values ? o->values[i] : i) == v)
                snprintf(buf, size, "%s", o->choices[i]);
        break;
    }
    case TS_OPT_TEXT: snprintf(buf, size, "%s", at); break;
    case TS_OPT_CUSTOM:
        if (!strcmp(o->name, "initial"))
            snprintf(buf, size, "equilibrium");
        break;
    default: break;
    }
}

/* ---- option sets --------------------------------------------------------- */

typedef struct given {
    char *text[MAX_TEXTS];
    int ntext;
    char where[WHERE_MAX];
} given;

struct ts_optset {
    ts_analysis_kind kind;
    const ts_option *table;
    int n;
    given (*g)[TS_OPTSET_COMMAND + 1]; /* [n][priority] */
};

ts_optset *ts_optset_alloc(ts_analysis_kind kind, ts_err *err)
{
    ts_optset *s = calloc(1, sizeof *s);
    if (s) {
        s->kind = kind;
        s->table = ts_options(kind, &s->n);
        s->g = calloc((size_t)s->n, sizeof *s->g);
    }
    if (!s || !s->g) {
        free(s);
        ts_fail(err, TS_ENOMEM, "options: out of memory");
        return NULL;
    }
    return s;
}

static void given_clear(given *g)
{
    for (int k = 0; k < g->ntext; k++)
        free(g->text[k]);
    g->ntext = 0;
}

void ts_optset_free(ts_optset *s)
{
    if (!s)
        return;
    for (int i = 0; i < s->n; i++)
        for (int p = 0; p <= TS_OPTSET_COMMAND; p++)
            given_clear(&s->g[i][p]);
    free(s->g);
    free(s);
}

static int row_index(const ts_optset *s, const char *name)
{
    const ts_option *o = ts_option_find(s->kind, name);
    return o ? (int)(o - s->table) : -1;
}

int ts_optset_give(ts_optset *s, const char *name, const char *text,
                   int priority, const char *where, ts_err *err)
{
    int i = row_index(s, name);
    if (i < 0)
        return ts_fail(err, TS_EINVAL, "%s: %s has no option '%s'", where,
                       ts_analysis_name(s->kind), name);
    if (priority < 0 || priority > TS_OPTSET_COMMAND)
        priority = TS_OPTSET_COMMAND;
    given *g = &s->g[i][priority];
    if (g->ntext > 0 && !(s->table[i].flags & TS_OPT_REPEAT)) {
        /* The last one counts on a command line, as in other tools. */
        given_clear(g);
    }
    if (g->ntext == MAX_TEXTS)
        return ts_fail(err, TS_EINVAL, "%s: given more than %d times", where,
                       MAX_TEXTS);
    g->text[g->ntext] = strdup(text ? text : "");
    if (!g->text[g->ntext])
        return ts_fail(err, TS_ENOMEM, "%s: out of memory", where);
    g->ntext++;
    snprintf(g->where, sizeof g->where, "%s", where);
    return TS_OK;
}

int ts_optset_give_entry(ts_optset *s, const ts_scene_analysis *a, int index,
                         const char *file, int priority, int section,
                         ts_err *err)
{
    int kind = ts_analysis_find(a->type);
    for (int i = 0; i < a->noptions; i++) {
        const ts_scene_option *so = &a->options[i];
        const ts_option *o = kind >= 0 ? ts_option_find(kind, so->key)
                                       : NULL;
        char where[WHERE_MAX];
        snprintf(where, sizeof where, "%s%sanalyses[%d].%s (line %d)",
                 file && file[0] ? file : "", file && file[0] ? ": " : "",
                 index, so->key, so->line);
        if (!o || strcmp(o->name, so->key) != 0) {
            int n;
            const ts_option *t = kind >= 0 ? ts_options(kind, &n) : NULL;
            char list[1024] = "";
            size_t len = 0;
            for (int j = 0; t && j < n; j++)
                len += (size_t)snprintf(list + len,
                                        len < sizeof list ? sizeof list - len
                                                          : 0,
                                        "%s%s", j ? ", " : "", t[j].name);
            return ts_fail(err, TS_ESCENE, "%s: unknown option for %s; "
                           "expected one of %s", where, a->type, list);
        }
        if (section >= 0 && (int)o->section != section)
            continue;
        if (!ts_option_find(s->kind, so->key))
            continue; /* a related entry's option the set has no row for */
        int rc = ts_optset_give(s, so->key, so->value, priority, where, err);
        if (rc)
            return rc;
    }
    return TS_OK;
}

int ts_optset_give_scene(ts_optset *s, const ts_scene *scene, int index,
                         ts_err *err)
{
    const char *kind = ts_analysis_name(s->kind);
    if (index >= scene->nanalyses ||
        (index >= 0 && strcmp(scene->analyses[index].type, kind) != 0))
        return ts_fail(err, TS_EINVAL, "analyses[%d]: %s", index,
                       index >= scene->nanalyses
                           ? "the scene has no such entry"
                           : "not an entry of this analysis");
    for (int i = 0; index < 0 && i < scene->nanalyses; i++)
        if (!strcmp(scene->analyses[i].type, kind))
            index = i;
    int rc = index >= 0 ? ts_optset_give_entry(s, &scene->analyses[index],
                                               index, scene->path,
                                               TS_OPTSET_SCENE, -1, err)
                        : TS_OK;
    /* A study of a simulation: below its own, the scene's first simulate
     * entry's simulation settings. */
    const char *an = ts_optset_text(s, "analysis");
    if (rc || s->kind != TS_ANALYSIS_CONVERGE || !an ||
        strcmp(an, "simulate") != 0)
        return rc;
    for (int i = 0; i < scene->nanalyses; i++)
        if (!strcmp(scene->analyses[i].type, "simulate"))
            return ts_optset_give_entry(s, &scene->analyses[i], i,
                                        scene->path, TS_OPTSET_RELATED,
                                        TS_SEC_SIMULATE, err);
    return TS_OK;
}

/* Checks of a request a lower source's value may yield in, at most. */
#define MAX_YIELDS 16

/* Apply the set up to priority max into rq (initialised here) and check
 * it against sys. */
static int request_check(const ts_optset *s, int max, const ts_system *sys,
                         const ts_units *u, ts_request *rq, ts_err *err)
{
    ts_request_init(rq, s->kind);
    int rc = ts_optset_apply(s, max, u, rq, err);
    return rc ? rc : ts_analysis_check(sys, rq, err);
}

int ts_optset_request(ts_optset *s, const ts_system *sys, const ts_units *u,
                      ts_request *rq, char *notes, size_t size, ts_err *err)
{
    if (notes && size)
        notes[0] = '\0';
    int rc = TS_OK;
    for (int k = 0; k <= MAX_YIELDS; k++) {
        ts_err_clear(err);
        rc = request_check(s, TS_OPTSET_COMMAND, sys, u, rq, err);
        if (rc == TS_OK)
            return TS_OK;
        /* A lower source's value that the higher one contradicts, and
         * that holds without it, yields to its default. */
        const char *key = ts_optset_yields(s, err);
        int ok_alone = 0;
        if (key && k < MAX_YIELDS) {
            ts_request alone;
            ok_alone = request_check(s, ts_optset_top(s) - 1, sys, u, &alone,
                                     NULL) == TS_OK;
            ts_request_clear(&alone);
        }
        ts_optset_locate(s, err);
        if (!ok_alone)
            break;
        if (notes && size) {
            size_t used = strlen(notes);
            snprintf(notes + used, size - used, "%s%s", used ? "\n" : "",
                     err->msg);
        }
        char name[TS_NAME_MAX];
        snprintf(name, sizeof name, "%s", key);
        ts_optset_drop(s, name);
        ts_request_clear(rq);
    }
    ts_request_clear(rq);
    return rc;
}

/* The priority <= max that wins for row i, or -1 when none gave it. */
static int winner_below(const ts_optset *s, int i, int max)
{
    for (int p = max; p >= 0; p--)
        if (s->g[i][p].ntext > 0)
            return p;
    return -1;
}

static int winner(const ts_optset *s, int i)
{
    return winner_below(s, i, TS_OPTSET_COMMAND);
}

int ts_optset_top(const ts_optset *s)
{
    int top = -1;
    for (int i = 0; i < s->n; i++) {
        int p = winner(s, i);
        top = p > top ? p : top;
    }
    return top;
}

const char *ts_optset_text(const ts_optset *s, const char *name)
{
    int i = row_index(s, name), p = i >= 0 ? winner(s, i) : -1;
    return p >= 0 ? s->g[i][p].text[0] : NULL;
}

const char *ts_optset_where(const ts_optset *s, const char *name)
{
    int i = row_index(s, name), p = i >= 0 ? winner(s, i) : -1;
    return p >= 0 ? s->g[i][p].where : NULL;
}

void ts_optset_drop(ts_optset *s, const char *name)
{
    int i = row_index(s, name);
    for (int p = 0; i >= 0 && p <= TS_OPTSET_COMMAND; p++)
        given_clear(&s->g[i][p]);
}

int ts_optset_apply(const ts_optset *s, int max_priority, const ts_units *u,
                    ts_request *rq, ts_err *err)
{
#define winner(s, i) winner_below(s, i, max_priority)
    /* Groups: the highest source wins; one source giving two is refused. */
    char *skip = calloc((size_t)s->n, 1);
    if (!skip)
        return ts_fail(err, TS_ENOMEM, "options: out of memory");
    for (int i = 0; i < s->n; i++) {
        int pi = winner(s, i);
        if (!s->table[i].group || pi < 0)
            continue;
        for (int j = i + 1; j < s->n; j++) {
            int pj = winner(s, j);
            if (s->table[j].group != s->table[i].group || pj < 0)
                continue;
            if (pi == pj) {
                free(skip);
                return ts_fail(err, TS_EINVAL, "%s and %s: give one of them "
                               "(%s or %s)", s->g[i][pi].where,
                               s->g[j][pj].where, s->table[i].name,
                               s->table[j].name);
            }
            skip[pi > pj ? j : i] = 1;
        }
    }
    int study = -1;
    for (int i = 0; i < s->n; i++) {
        int p = winner(s, i);
        if (p < 0 || skip[i])
            continue;
        const given *g = &s->g[i][p];
        for (int k = 0; k < g->ntext; k++) {
            int rc = ts_option_set(&s->table[i], rq, g->text[k], g->where, u,
                                   err);
            if (rc) {
                free(skip);
                return rc;
            }
        }
        if (s->table[i].offset == offsetof(ts_request, converge.analysis))
            study = rq->converge.analysis;
    }
    free(skip);
    /* Options of a study that do not apply to its analysis. */
    if (s->kind == TS_ANALYSIS_CONVERGE) {
        if (study < 0)
            study = rq->converge.analysis;
        for (int i = 0; i < s->n; i++) {
            int p = winner(s, i);
            const ts_option *o = &s->table[i];
            if (p < 0 || !o->only || o->only == study + 1)
                continue;
            /* A related entry's settings are taken as they apply. */
            if (p == TS_OPTSET_RELATED)
                continue;
            return ts_fail(err, TS_EINVAL, "%s: applies to a study of %s "
                           "(analysis %s), not of %s", s->g[i][p].where,
                           ts_analysis_name(o->only - 1),
                           ts_analysis_name(o->only - 1),
                           ts_analysis_name(study));
        }
    }
    return TS_OK;
#undef winner
}

/* The row and winning priority an error message starts with ("key: "). */
static int message_row(const ts_optset *s, const ts_err *err, int *prio)
{
    if (!err)
        return -1;
    const char *colon = strchr(err->msg, ':');
    if (!colon || colon == err->msg || (size_t)(colon - err->msg) >= 64)
        return -1;
    char key[64];
    snprintf(key, sizeof key, "%.*s", (int)(colon - err->msg), err->msg);
    for (int i = 0; i < s->n; i++)
        if (!strcmp(s->table[i].name, key)) {
            *prio = winner(s, i);
            return i;
        }
    return -1;
}

void ts_optset_locate(const ts_optset *s, ts_err *err)
{
    int p, i = message_row(s, err, &p);
    if (i < 0 || p < 0)
        return;
    char rest[TS_ERR_MSG_MAX];
    snprintf(rest, sizeof rest, "%s", err->msg + strlen(s->table[i].name));
    snprintf(err->msg, sizeof err->msg, "%s%s", s->g[i][p].where, rest);
}

const char *ts_optset_yields(const ts_optset *s, const ts_err *err)
{
    int p, i = message_row(s, err, &p);
    if (i < 0 || p < 0 || !(s->table[i].flags & TS_OPT_YIELD))
        return NULL;
    return p < ts_optset_top(s) ? s->table[i].name : NULL;
}
