/* cli_plot.c: --plot DIR and --units for the subcommands (cli_plot.h). */
#include "cli_plot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

/* Room for a quantity as written in a legend. */
#define ITEM_TEXT 96

int cli_plot_begin(cli_plot *p, const char *cmd)
{
    const ts_display *d = p->opts.display; /* the caller's, kept */
    ts_plot_opts_default(&p->opts);
    p->opts.display = d;
    if (!p->dir)
        return 0;
    ts_err err = {0};
    int check = ts_plot_check(&err);
    if (check != TS_OK) {
        fprintf(stderr, "towstab: error: %s: --plot: %s\n", cmd, err.msg);
        /* A drawing module that cannot be loaded is a fault of the
         * installation (TS_EIO), a build without PLplot a request this
         * towstab cannot serve (bad input). */
        return check == TS_EIO ? EXIT_FAILED : EXIT_BADINPUT;
    }
    struct stat st;
    int existed = stat(p->dir, &st) == 0;
    int rc = ts_plot_prepare_dir(p->dir, &err);
    if (rc != TS_OK) {
        fprintf(stderr, "towstab: error: %s: --plot: %s\n", cmd, err.msg);
        return rc == TS_EINVAL ? EXIT_BADINPUT : EXIT_FAILED;
    }
    p->made = !existed;
    return 0;
}

void cli_plot_abandon(cli_plot *p)
{
    /* rmdir removes only an empty directory: pictures drawn stay. */
    if (p->dir && p->made && rmdir(p->dir) == 0)
        p->made = 0;
}

void cli_plot_wrote(const cli_plot *p, const char *name)
{
    int png = p->opts.formats & TS_PLOT_PNG, svg = p->opts.formats & TS_PLOT_SVG;
    printf("wrote");
    if (png)
        printf(" %s/%s.png", p->dir, name);
    if (svg)
        printf("%s %s/%s.svg", png ? " and" : "", p->dir, name);
    printf("\n");
}

int cli_display_begin(const ts_units *units, const char *spec,
                      ts_display *d)
{
    ts_display_si(d);
    if (!spec)
        return 0;
    ts_err err = {0};
    int rc = ts_display_parse(units, spec, "--units", d, &err);
    return rc ? cli_report(&err, rc) : 0;
}

int cli_plot_shape(const ts_system *sys, const ts_equilibrium *eq,
                   const double *pos, cli_shape *out)
{
    memset(out, 0, sizeof *out);
    out->link_upper = malloc(((size_t)sys->nlinks + 1) * sizeof(int));
    out->marks = malloc(((size_t)sys->nbodies + 1) * sizeof(int));
    out->cylinders = malloc(((size_t)sys->nbodies + 1) *
                            sizeof *out->cylinders);
    if (!out->link_upper || !out->marks || !out->cylinders) {
        cli_plot_shape_free(out);
        return -1;
    }
    /* Link l joins its upper node to node l + 1 (ts_link.lower). */
    for (int l = 0; l < sys->nlinks; l++)
        out->link_upper[l] = sys->links[l].upper;
    int nmarks = 0, ncyl = 0;
    for (int b = 0; b < sys->nbodies; b++) {
        const ts_body *B = &sys->bodies[b];
        int node = ts_system_body_node(sys, b);
        if (B->type == TS_BODY_SPHERE)
            out->marks[nmarks++] = node;
        else if (B->type == TS_BODY_CYLINDER && node >= 1 &&
                 B->length > 0 && B->diameter > 0)
            out->cylinders[ncyl++] =
                (ts_plot_cylinder){node, B->length, B->diameter};
    }
    ts_plot_shape *s = &out->shape;
    s->nnodes = sys->nnodes;
    s->pos = pos;
    s->link_upper = out->link_upper;
    s->nmarks = nmarks;
    s->marks = out->marks;
    s->ncylinders = ncyl;
    s->cylinders = out->cylinders;
    /* doc/model.md section 1: the turn centre is at (0, V / Omega, 0),
     * with a towing vehicle at its solved motion. */
    double V, W;
    cli_steady_motion(sys, eq, &V, &W);
    s->turn_radius = W != 0 ? V / W : 0;
    s->label = out->label;
    return 0;
}

void cli_plot_shape_free(cli_shape *s)
{
    free(s->link_upper);
    free(s->marks);
    free(s->cylinders);
    s->link_upper = s->marks = NULL;
    s->cylinders = NULL;
    for (int b = 0; s->outlines && b < s->shape.noutlines; b++)
        free((double *)s->outlines[b].pts);
    free(s->outlines);
    s->outlines = NULL;
    s->shape.outlines = NULL;
    s->shape.noutlines = 0;
}

int cli_plot_add_vehicle(cli_shape *s, const ts_system *sys, int b,
                         const double R[9], const double *delta)
{
    const ts_vehicle *v = sys->bodies[b].vehicle;
    if (!v)
        return 0;
    if (!s->outlines) {
        s->outlines = calloc((size_t)sys->nbodies, sizeof *s->outlines);
        if (!s->outlines)
            return -1;
        s->shape.outlines = s->outlines;
    }
    /* The attach point is the body's node; the origin O = A - R a. */
    const double *A = s->shape.pos + 3 * ts_system_body_node(sys, b);
    double O[3];
    for (int i = 0; i < 3; i++)
        O[i] = A[i] - (R[3 * i] * v->attach[0] + R[3 * i + 1] * v->attach[1] +
                       R[3 * i + 2] * v->attach[2]);
    int n = ts_vehicle_outline(v, R, O, delta, NULL, 0);
    double *pts = malloc(3 * (size_t)(n > 0 ? n : 1) * sizeof(double));
    if (!pts)
        return -1;
    ts_vehicle_outline(v, R, O, delta, pts, n);
    ts_plot_outline *o = &s->outlines[s->shape.noutlines++];
    o->npoints = n;
    o->pts = pts;
    memcpy(o->anchor, A, sizeof o->anchor);
    return 0;
}

int cli_plot_add_vehicles(cli_shape *s, const ts_system *sys,
                          const ts_equilibrium *eq)
{
    for (int i = 0; i < eq->nvehicles; i++)
        if (cli_plot_add_vehicle(s, sys, eq->vehicles[i].body,
                                 eq->vehicles[i].R, eq->vehicles[i].delta))
            return -1;
    return 0;
}

void cli_plot_tow_label(const ts_system *sys, const ts_equilibrium *eq,
                        const char *speed_text, const char *turn_text,
                        const ts_display *d, char *buf, size_t size)
{
    d = ts_display_or_si(d);
    char v[ITEM_TEXT], w[ITEM_TEXT];
    /* A towing vehicle's solved motion replaces the texts as written
     * (the solve's start). */
    double V, W;
    cli_steady_motion(sys, eq, &V, &W);
    if (cli_motion_solved(sys, eq))
        speed_text = turn_text = NULL;
    if (speed_text && speed_text[0])
        snprintf(v, sizeof v, "%s", speed_text);
    else
        snprintf(v, sizeof v, "%.4g %s", ts_display_value(d, TS_QTY_SPEED, V),
                 ts_display_unit(d, TS_QTY_SPEED));
    if (W == 0) {
        snprintf(buf, size, "%s, straight", v);
        return;
    }
    if (turn_text && turn_text[0])
        snprintf(w, sizeof w, "%s", turn_text);
    else
        snprintf(w, sizeof w, "%.4g %s",
                 ts_display_value(d, TS_QTY_ANGULAR_RATE, fabs(W)),
                 ts_display_unit(d, TS_QTY_ANGULAR_RATE));
    snprintf(buf, size, "%s, turn %s (%s)", v, w,
             W > 0 ? "starboard" : "port");
}
