/* cmd_equilibrium.c: `towstab equilibrium SCENE` and the `equilibrium`
 * analysis of a scene: the steady shape (doc/equilibrium.md), printed as
 * node, link and body tables with the verdict.
 *
 * Pictures (--plot DIR): side and top views of the cable (side.png/svg,
 * top.png/svg), with overlays of other speeds, turn rates or scenes
 * solved with the same settings (doc/plots.md). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "cli_plot.h"
#include "towstab/kernel.h"

/* At most this many overlay curves (speeds, turn rates and scenes). */
#define MAX_OVERLAYS 8
#define ITEM_MAX 128

/* One curve of the pictures: a system and its equilibrium. */
typedef struct eq_curve {
    const ts_system *sys;
    const ts_equilibrium *eq;
    ts_result *res;    /* an overlay's result (owned), else NULL */
    ts_scene *scene;   /* an --overlay scene (owned), else NULL */
    ts_request rq;     /* an overlay's request (a shallow copy) */
    char what[ITEM_MAX + 64];
    char speed_text[ITEM_MAX], turn_text[ITEM_MAX]; /* as written, for the
                          legend ("" when not written: display units) */
} eq_curve;

/* What the pictures need: the overlays, checked before the first solve. */
typedef struct eq_state {
    eq_curve curves[MAX_OVERLAYS + 1];
    int ncurves;
} eq_state;

/* Split "2,4,6 knot" into items; items without a unit take the unit of
 * the last item ("2 knot", "4 knot", "6 knot"). Returns the number of
 * items, or -1 after printing a message. */
static int split_list(const char *opt, const char *text,
                      char items[][ITEM_MAX], int max)
{
    char buf[MAX_OVERLAYS * ITEM_MAX];
    if (strlen(text) >= sizeof buf) {
        fprintf(stderr, "towstab: error: equilibrium: %s: list too long\n", opt);
        return -1;
    }
    strcpy(buf, text);
    int n = 0;
    /* Split at every comma (an empty item is an error, unlike strtok). */
    for (char *tok = buf, *next; tok; tok = next) {
        next = strchr(tok, ',');
        if (next)
            *next++ = '\0';
        while (*tok == ' ')
            tok++;
        size_t len = strlen(tok);
        while (len > 0 && tok[len - 1] == ' ')
            tok[--len] = '\0';
        if (len == 0 || len >= ITEM_MAX || n == max) {
            fprintf(stderr, "towstab: error: equilibrium: %s: expected 1 to %d "
                            "comma-separated values like '2,4,6 knot', got "
                            "'%s'\n",
                    opt, max, text);
            return -1;
        }
        strcpy(items[n++], tok);
    }
    if (n == 0) {
        fprintf(stderr, "towstab: error: equilibrium: %s: expected values like "
                        "'2,4,6 knot', got '%s'\n",
                opt, text);
        return -1;
    }
    /* A unit written on some items applies to those written without one
     * ('2,4,6 knot'). */
    const char *text_of[MAX_OVERLAYS];
    for (int i = 0; i < n; i++)
        text_of[i] = items[i];
    char unit[CLI_UNIT_TEXT_MAX];
    if (cli_shared_unit("equilibrium", opt, text_of, n, unit, sizeof unit))
        return -1;
    for (int i = 0; unit[0] && i < n; i++) {
        char *e;
        strtod(items[i], &e);
        while (*e == ' ')
            e++;
        if (*e == '\0' && strlen(items[i]) + strlen(unit) + 2 < ITEM_MAX) {
            strcat(items[i], " ");
            strcat(items[i], unit);
        }
    }
    return n;
}

/* "a", "a and b", "a, b and c" of the distinct scene names. */
static void scene_names(const eq_curve *curves, int n, char *buf,
                        size_t size, int *distinct)
{
    const char *names[MAX_OVERLAYS + 1];
    int nn = 0;
    for (int i = 0; i < n; i++) {
        if (!curves[i].sys)
            continue;
        int seen = 0;
        for (int j = 0; j < nn; j++)
            seen |= strcmp(names[j], curves[i].sys->name) == 0;
        if (!seen)
            names[nn++] = curves[i].sys->name;
    }
    buf[0] = '\0';
    for (int j = 0; j < nn; j++) {
        size_t len = strlen(buf);
        snprintf(buf + len, size - len, "%s%s",
                 j == 0 ? "" : j == nn - 1 ? " and " : ", ", names[j]);
    }
    *distinct = nn;
}

/* Points of a circle of a steady turn in the earth-frame plan view. */
#define TURN_POINTS 361

/* One point at rest in M over one steady turn, as a track in the earth
 * frame R (doc/model.md section 1): M's origin at heading psi = Omega t is
 * at (Rt sin psi, Rt (1 - cos psi)), Rt = V / Omega, and the point r of M
 * at that origin plus R_z(psi) r. Exact: no integration. */
static void turn_track(double speed, double turn_rate, const double r[3],
                       double *x, double *y)
{
    double Rt = speed / turn_rate;
    for (int k = 0; k < TURN_POINTS; k++) {
        double psi = copysign(2 * M_PI, turn_rate) * k / (TURN_POINTS - 1);
        double c = cos(psi), s = sin(psi);
        x[k] = Rt * s + c * r[0] - s * r[1];
        y[k] = Rt * (1 - c) + s * r[0] + c * r[1];
    }
}

/* 1 when curve (sys, eq) is a steady turn, with its speed and turn rate
 * (a towing vehicle's solved ones) in *speed, *turn_rate (either NULL). */
static int turning(const ts_system *sys, const ts_equilibrium *eq,
                   double *speed, double *turn_rate)
{
    double V, W;
    cli_steady_motion(sys, eq, &V, &W);
    if (speed)
        *speed = V;
    if (turn_rate)
        *turn_rate = W;
    return W != 0 && V > 0;
}

/* The earth-frame plan view of the converged curves in a steady turn
 * (plan_earth): over one turn, the circle of the tow point and of every
 * body, each marked where it is at t = 0. Nothing is drawn when no curve
 * turns. Returns the exit status. */
static int eq_plot_turn(const cli_plot *plot, const eq_curve *curves,
                        int ncurves, const char *names, int distinct)
{
    int ntracks = 0;
    for (int i = 0; i < ncurves; i++)
        if (curves[i].eq && curves[i].eq->converged &&
            turning(curves[i].sys, curves[i].eq, NULL, NULL))
            ntracks += 1 + curves[i].sys->nbodies;
    if (ntracks == 0)
        return 0;
    ts_plot_track *t = calloc((size_t)ntracks, sizeof *t);
    ts_plot_marker *m = calloc((size_t)ntracks, sizeof *m);
    double *xy = malloc(2 * (size_t)ntracks * TURN_POINTS * sizeof *xy);
    char (*label)[192] = calloc((size_t)ntracks, sizeof *label);
    if (!t || !m || !xy || !label) {
        free(t);
        free(m);
        free(xy);
        free(label);
        fprintf(stderr, "towstab: error: equilibrium: --plot: out of memory\n");
        return EXIT_FAILED;
    }
    int n = 0, curve = 0;
    for (int i = 0; i < ncurves; i++) {
        const eq_curve *c = &curves[i];
        double V, W;
        if (!c->eq || !c->eq->converged || !turning(c->sys, c->eq, &V, &W))
            continue;
        char tow[128];
        cli_plot_tow_label(c->sys, c->eq, c->speed_text, c->turn_text,
                           plot->opts.display, tow, sizeof tow);
        for (int b = -1; b < c->sys->nbodies; b++) {
            int node = b < 0 ? 0 : ts_system_body_node(c->sys, b);
            const char *what = b < 0 ? "tow point" : c->sys->bodies[b].name;
            double *x = xy + 2 * (size_t)n * TURN_POINTS, *y = x + TURN_POINTS;
            turn_track(V, W, c->eq->positions + 3 * node, x, y);
            if (distinct > 1 || curve > 0)
                snprintf(label[n], sizeof label[n], "%.40s %.40s, %.100s",
                         distinct > 1 ? c->sys->name : "", what, tow);
            else
                snprintf(label[n], sizeof label[n], "%s", what);
            m[n] = (ts_plot_marker){x[0], y[0], b < 0 ? "t = 0" : NULL};
            /* The tow point solid, the bodies dashed. */
            t[n] = (ts_plot_track){TURN_POINTS, x, y, label[n],
                                   b < 0 ? TS_PLOT_SOLID : TS_PLOT_DASHED,
                                   1 + n, 1, &m[n]};
            n++;
        }
        curve++;
    }
    char title[640];
    snprintf(title, sizeof title, "%s: steady turn over one revolution, "
             "earth frame", names);
    ts_err err = {0};
    int status = 0;
    if (ts_plot_tracks(plot->dir, "plan_earth", title, n, t, &plot->opts,
                       &err) != TS_OK)
        status = cli_report(&err, err.code);
    else
        cli_plot_wrote(plot, "plan_earth");
    free(t);
    free(m);
    free(xy);
    free(label);
    return status;
}

/* Side and top views of the converged curves. Returns the exit status. */
static int eq_plot(const cli_plot *plot, eq_curve *curves, int ncurves)
{
    cli_shape shapes[MAX_OVERLAYS + 1];
    ts_plot_shape sh[MAX_OVERLAYS + 1];
    int n = 0, water = 0, status = 0;
    char names[512];
    int distinct;
    scene_names(curves, ncurves, names, sizeof names, &distinct);
    double x0 = 0, x1 = 0, z0 = 0, z1 = 0;
    for (int i = 0; i < ncurves; i++) {
        const eq_curve *c = &curves[i];
        if (!c->eq || !c->eq->converged)
            continue;
        if (cli_plot_shape(c->sys, c->eq, c->eq->positions, &shapes[n]) != 0 ||
            cli_plot_add_vehicles(&shapes[n], c->sys, c->eq) != 0) {
            fprintf(stderr, "towstab: error: equilibrium: --plot: out of memory\n");
            status = EXIT_FAILED;
            break;
        }
        char tow[128];
        cli_plot_tow_label(c->sys, c->eq, c->speed_text, c->turn_text,
                           plot->opts.display, tow, sizeof tow);
        if (distinct > 1)
            snprintf(shapes[n].label, sizeof shapes[n].label, "%.63s: %.120s",
                     c->sys->name, tow);
        else
            snprintf(shapes[n].label, sizeof shapes[n].label, "%s", tow);
        water |= c->sys->env.water_density > 0;
        for (int k = 0; k < c->sys->nnodes; k++) {
            const double *r = c->eq->positions + 3 * k;
            x0 = r[0] < x0 ? r[0] : x0;
            x1 = r[0] > x1 ? r[0] : x1;
            z0 = r[2] < z0 ? r[2] : z0;
            z1 = r[2] > z1 ? r[2] : z1;
        }
        sh[n] = shapes[n].shape;
        n++;
    }
    if (n == 0 && status == 0) {
        fprintf(stderr, "towstab: error: equilibrium: --plot: no converged "
                        "equilibrium to draw\n");
        status = EXIT_FAILED;
    }
    /* The side view keeps the true shape (equal scales) unless the cable
     * is so flat that its depth would be under 5 % of its length. */
    int flags = (water ? TS_PLOT_WATER : 0) |
                (z1 - z0 >= 0.05 * (x1 - x0) ? TS_PLOT_EQUAL : 0);
    static const char *const view_name[2] = {"side", "top"};
    for (int v = 0; v < 2 && status == 0; v++) {
        char title[640];
        snprintf(title, sizeof title, "%s: equilibrium, %s view", names,
                 view_name[v]);
        ts_err err = {0};
        int rc = ts_plot_shapes(plot->dir, view_name[v], title,
                                v ? TS_PLOT_TOP : TS_PLOT_SIDE, flags, n, sh,
                                &plot->opts, &err);
        if (rc != TS_OK)
            status = cli_report(&err, rc);
        else
            cli_plot_wrote(plot, view_name[v]);
    }
    if (status == 0)
        status = eq_plot_turn(plot, curves, ncurves, names, distinct);
    for (int i = 0; i < n; i++)
        cli_plot_shape_free(&shapes[i]);
    return status;
}

void cli_print_equilibrium(const ts_result *r, int quiet,
                           const ts_display *d)
{
    if (!r->eq || !r->eq_attempted)
        return;
    FILE *f = stdout;
    const ts_system *sys = r->sys;
    const ts_equilibrium *eq = r->eq;
    double wall_s = r->eq_wall_s;
    /* The equilibrium's own verdict; an equilibrium analysis' is the
     * result's (which also says why a failed run failed). */
    const ts_trust *t = r->kind == TS_ANALYSIS_EQUILIBRIUM ? &r->trust
                                                           : &r->eq_trust;
    const char *lu = ts_display_unit(d, TS_QTY_LENGTH);
    const char *fu = ts_display_unit(d, TS_QTY_FORCE);
#define L_(v) ts_display_value(d, TS_QTY_LENGTH, (v))
#define F_(v) ts_display_value(d, TS_QTY_FORCE, (v))
    char tow[256];
    cli_tow_text(sys, eq, d, tow, sizeof tow);
    fprintf(f, "%s, %d cable%s, %d links, %d bod%s\n", tow, sys->ncables,
            sys->ncables == 1 ? "" : "s", sys->nlinks, sys->nbodies,
            sys->nbodies == 1 ? "y" : "ies");
    /* A failed solve may end on forces that overflowed: no "nan". */
    char res[64];
    if (isfinite(eq->residual) && isfinite(eq->force_scale))
        snprintf(res, sizeof res, "%.3g of %.6g %s", eq->residual,
                 F_(eq->force_scale), fu);
    else
        snprintf(res, sizeof res, "not finite");
    fprintf(f, "%s: %s, %d iterations, %ld evaluations, residual %s "
               "(target %.3g), %.3f ms\n",
            eq->converged ? "converged" : "NOT CONVERGED",
            ts_eq_method_name(eq->method), eq->iterations, eq->evaluations,
            res, eq->tolerance, wall_s * 1e3);
    if (!eq->converged) {
        if (r->kind == TS_ANALYSIS_EQUILIBRIUM)
            cli_print_trust(t);
        return;
    }
    char name[2 * TS_NAME_MAX], h[3][48];
    if (!quiet) {
        for (int c = 0; c < 3; c++)
            snprintf(h[c], sizeof h[c], "%c [%s]", "xyz"[c], lu);
        fprintf(f, "\n%-20s %14s %14s %14s\n", "node", h[0], h[1], h[2]);
        for (int i = 0; i < sys->nnodes; i++) {
            const double *p = eq->positions + 3 * i;
            ts_system_node_name(sys, i, name, sizeof name);
            fprintf(f, "%-20s %14.6f %14.6f %14.6f\n", name, L_(p[0]),
                    L_(p[1]), L_(p[2]));
        }
        snprintf(h[0], sizeof h[0], "tension [%s]", fu);
        fprintf(f, "\n%-20s %6s %14s %14s %14s%s\n", "cable", "link", h[0],
                "theta1 [deg]", "theta2 [deg]",
                sys->has_elastic ? "         strain" : "");
        for (int l = 0; l < sys->nlinks; l++) {
            const ts_link *L = &sys->links[l];
            double t1, t2;
            ts_direction_angles(eq->directions + 3 * l, &t1, &t2);
            fprintf(f, "%-20s %6d %14.6f %14.6f %14.6f",
                    sys->cables[L->cable].name, L->index, F_(eq->tensions[l]),
                    t1 * 180 / M_PI, t2 * 180 / M_PI);
            if (L->elastic)
                fprintf(f, " %14.6e", ts_equilibrium_strain(sys, eq, l));
            fprintf(f, "\n");
        }
    }
    /* The key values of an equilibrium are x, y, z of each body (or free
     * cable end), then the top tension, then a towing vehicle's solved
     * motion: their errors go beside them. */
    const ts_value *top = r->kind == TS_ANALYSIS_EQUILIBRIUM
                              ? ts_result_value(r, "top_tension")
                              : NULL;
    int ntop = top ? (int)(top - r->values) : -1;
    int own = top && ntop == 3 * (sys->nbodies > 0 ? sys->nbodies : 0);
    if (sys->nbodies > 0) {
        for (int c = 0; c < 3; c++)
            snprintf(h[c], sizeof h[c], "%c [%s]%s", "xyz"[c], lu,
                     c == 2 ? " (depth)" : "");
        fprintf(f, "\n%-20s %14s %14s %14s\n", "body", h[0], h[1], h[2]);
        for (int b = 0; b < sys->nbodies; b++) {
            const double *p = eq->positions + 3 * ts_system_body_node(sys, b);
            fprintf(f, "%-20s %14.6f %14.6f %14.6f\n", sys->bodies[b].name,
                    L_(p[0]), L_(p[1]), L_(p[2]));
            if (!own || !r->accuracy.estimated)
                continue;
            fprintf(f, "%-20s", "  +- discretisation");
            for (int j = 0; j < 3; j++)
                fprintf(f, " %14.2g",
                        L_(r->values[3 * b + j].error.discretisation));
            fprintf(f, "\n");
        }
    }
    cli_print_vehicles(f, sys, eq->vehicles, eq->nvehicles, quiet, d);
    /* A towing vehicle's solved motion with its errors. */
    for (int v = ntop + 1; top && v < r->nvalues; v++) {
        char e[128], u[64];
        cli_value_error(&r->values[v], d, e, sizeof e);
        ts_display_convert(ts_display_or_si(d), r->values[v].unit, 1.0, u,
                           sizeof u);
        fprintf(f, "%s %.9g %s %s\n", r->values[v].name,
                cli_value_shown(&r->values[v], d), u, e);
    }
    if (eq->ncontrol > 0)
        fprintf(f, "controllers settled to %.3g (target %.3g)\n",
                eq->control_residual, eq->tolerance);
    for (int c = 0; c < sys->ncables; c++)
        if (sys->cables[c].ea > 0) {
            double len = ts_equilibrium_cable_length(sys, eq, c);
            fprintf(f, "%scable %s: stretched length %.9g %s (%.6g %s at "
                       "rest, strain %.4g)\n",
                    c == 0 || !(sys->cables[c - 1].ea > 0) ? "\n" : "",
                    sys->cables[c].name, L_(len), lu,
                    L_(sys->cables[c].length), lu,
                    len / sys->cables[c].length - 1);
        }
    fprintf(f, "\ntop tension %.6f %s", F_(eq->top_tension), fu);
    if (top) {
        char e[128];
        cli_value_error(top, d, e, sizeof e);
        fprintf(f, " %s", e);
    }
    fprintf(f, " (force on the tow point %.6f, %.6f, %.6f %s)\n",
            F_(eq->tow_force[0]), F_(eq->tow_force[1]),
            F_(eq->tow_force[2]), fu);
    fprintf(f, "solver Jacobian condition %.3g, shape error estimate %.3g "
               "%s\n",
            eq->condition, L_(eq->shape_error), lu);
    if (r->kind == TS_ANALYSIS_EQUILIBRIUM) {
        /* Free cable ends (no bodies): their key values. */
        for (int v = 0; sys->nbodies == 0 && v < ntop; v++) {
            char e[128];
            cli_value_error(&r->values[v], d, e, sizeof e);
            fprintf(f, "%s %.6f %s %s\n", r->values[v].name,
                    cli_value_shown(&r->values[v], d), lu, e);
        }
        cli_print_accuracy(r);
        cli_print_trust(t);
    } else if (r->status == TS_OK) {
        /* Another analysis' equilibrium: its solve is judged here, its
         * values' discretisation error is towstab equilibrium's. When that
         * analysis failed after it, the result asked for was not
         * delivered: no verdict (stderr says why). */
        cli_print_trust_as(t, "equilibrium solve (its discretisation "
                              "error: towstab equilibrium)");
    }
#undef L_
#undef F_
}


/* Solve an overlay's equilibrium (before the main analysis prints
 * anything: a refused overlay refuses the run). Returns the exit status
 * (0 when converged). */
static int overlay_solve(const cli_run *c, eq_curve *cv)
{
    ts_err err = {0};
    const ts_system *sys = (cv->scene ? cv->scene : c->scene)->system;
    int rc = ts_analysis_run(sys, &cv->rq, &cv->res, &err);
    if (rc != TS_OK) {
        ts_err_prefix(&err, "%s: ", cv->what);
        return cli_report(&err, rc);
    }
    cv->sys = cv->res->sys;
    cv->eq = cv->res->eq;
    return 0;
}

/* The extras: --overlay-speeds, --overlay-turn-rates, --overlay. */
enum { X_SPEEDS, X_TURNS, X_SCENES };

/* Check the overlays, build their requests and solve them (before the
 * main analysis runs). */
static int eq_prepare(cli_run *c)
{
    int given = c->nextra[X_SPEEDS] + c->nextra[X_TURNS] +
                c->nextra[X_SCENES];
    if (given && !c->plot.dir) {
        fprintf(stderr, "towstab: error: equilibrium: --overlay-speeds, "
                        "--overlay-turn-rates and --overlay add curves to the "
                        "--plot pictures; add --plot DIR\n");
        return EXIT_BADINPUT;
    }
    if (!c->plot.dir)
        return 0;
    eq_state *st = calloc(1, sizeof *st);
    if (!st) {
        fprintf(stderr, "towstab: error: equilibrium: out of memory\n");
        return EXIT_FAILED;
    }
    c->state = st;
    st->ncurves = 1;
    /* The main curve's speed and turn rate as written: on the command
     * line or in the scene's entry (the option's text), else in the
     * scene's tow. */
    eq_curve *main_curve = &st->curves[0];
    const char *sp = ts_optset_text(c->opts, "speed");
    const char *tr = ts_optset_text(c->opts, "turn_rate");
    snprintf(main_curve->speed_text, ITEM_MAX, "%s",
             sp ? sp : c->scene->speed_text);
    snprintf(main_curve->turn_text, ITEM_MAX, "%s",
             tr ? tr : c->scene->turn_rate_text);
    char items[2][MAX_OVERLAYS][ITEM_MAX];
    int nitems[2] = {0, 0};
    static const char *const opt[2] = {"--overlay-speeds",
                                       "--overlay-turn-rates"};
    for (int k = 0; k < 2; k++)
        if (c->nextra[k] &&
            (nitems[k] = split_list(opt[k], c->extra[k][0], items[k],
                                    MAX_OVERLAYS)) < 0)
            return EXIT_BADINPUT;
    int total = nitems[0] + nitems[1] + c->nextra[X_SCENES];
    if (total > MAX_OVERLAYS) {
        fprintf(stderr, "towstab: error: equilibrium: at most %d overlay "
                        "curves in all, got %d\n",
                MAX_OVERLAYS, total);
        return EXIT_BADINPUT;
    }
    ts_err err = {0};
    for (int i = 0; i < total; i++) {
        eq_curve *cv = &st->curves[st->ncurves++];
        cv->rq = c->rq;
        cv->rq.simulate.excitation = NULL;
        const ts_scene *from = c->scene;
        int rc = TS_OK;
        if (i < nitems[0] + nitems[1]) {
            int k = i < nitems[0] ? 0 : 1;
            const char *item = items[k][k ? i - nitems[0] : i];
            snprintf(cv->what, sizeof cv->what, "%s '%.120s'", opt[k], item);
            snprintf(cv->speed_text, ITEM_MAX, "%s",
                     k ? main_curve->speed_text : item);
            snprintf(cv->turn_text, ITEM_MAX, "%s",
                     k ? item : main_curve->turn_text);
            rc = ts_option_set(ts_option_find(TS_ANALYSIS_EQUILIBRIUM,
                                              k ? "turn_rate" : "speed"),
                               &cv->rq, item, cv->what, c->units, &err);
        } else {
            const char *path = c->extra[X_SCENES][i - nitems[0] - nitems[1]];
            snprintf(cv->what, sizeof cv->what, "--overlay '%.120s'", path);
            cv->scene = ts_scene_load(path, c->units, &err);
            if (!cv->scene) {
                ts_err_prefix(&err, "%s: ", cv->what);
                return cli_report(&err, err.code == TS_EIO ? TS_ESCENE
                                                           : err.code);
            }
            from = cv->scene;
            snprintf(cv->speed_text, ITEM_MAX, "%s",
                     sp ? sp : cv->scene->speed_text);
            snprintf(cv->turn_text, ITEM_MAX, "%s",
                     tr ? tr : cv->scene->turn_rate_text);
        }
        if (rc == TS_OK)
            rc = ts_analysis_check(from->system, &cv->rq, &err);
        if (rc != TS_OK) {
            if (strncmp(err.msg, cv->what, strlen(cv->what)) != 0)
                ts_err_prefix(&err, "%s: ", cv->what);
            return cli_report(&err, rc);
        }
    }
    for (int i = 1; i < st->ncurves; i++) {
        int status = overlay_solve(c, &st->curves[i]);
        if (status)
            return status;
    }
    return 0;
}

static void eq_print(const cli_run *c, const ts_result *r)
{
    cli_print_equilibrium(r, c->quiet, &c->display);
}

static int eq_draw(cli_run *c, const ts_result *r)
{
    eq_state *st = c->state;
    if (!st)
        return 0;
    st->curves[0].sys = r->sys;
    st->curves[0].eq = r->eq && r->eq->converged ? r->eq : NULL;
    for (int i = 1; i < st->ncurves; i++) {
        const eq_curve *cv = &st->curves[i];
        printf("overlay %s: converged (%s), top tension %.6f %s\n", cv->what,
               ts_eq_method_name(cv->eq->method),
               ts_display_value(&c->display, TS_QTY_FORCE,
                                cv->eq->top_tension),
               ts_display_unit(&c->display, TS_QTY_FORCE));
    }
    return eq_plot(&c->plot, st->curves, st->ncurves);
}

static void eq_release(cli_run *c)
{
    eq_state *st = c->state;
    for (int i = 1; st && i < st->ncurves; i++) {
        ts_result_free(st->curves[i].res);
        ts_scene_free(st->curves[i].scene);
    }
    free(st);
    c->state = NULL;
}

static const cli_extra eq_extras[] = {
    {"overlay-speeds", 1, 0, "LIST",
     "also draw these speeds ('2,4,6 knot'; needs --plot)"},
    {"overlay-turn-rates", 1, 0, "LIST",
     "also draw these turn rates ('0.2,0.5 rad/s'; needs --plot)"},
    {"overlay", 1, 1, "SCENE",
     "also draw this scene (repeatable); the options above apply to every "
     "curve"},
    {NULL, 0, 0, NULL, NULL}};

static const char *const eq_pictures[] = {"side", "top", NULL};

const cli_command cli_cmd_equilibrium = {
    "equilibrium", "steady shape at the scene's speed and turn rate",
    TS_ANALYSIS_EQUILIBRIUM, NULL, eq_prepare, eq_print, eq_draw,
    eq_release, eq_pictures, eq_extras, NULL};
