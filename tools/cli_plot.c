/* cli_plot.c: --plot DIR and --units for the subcommands (cli_plot.h). */
#include "cli_plot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

int cli_plot_begin(cli_plot *p, const char *cmd)
{
    ts_plot_opts_default(&p->opts);
    if (!p->dir) {
        if (p->units) {
            fprintf(stderr, "towstab: error: %s: --units sets the units of the "
                            "--plot pictures; add --plot DIR\n",
                    cmd);
            return EXIT_BADINPUT;
        }
        return 0;
    }
    ts_err err = {0};
    if (ts_plot_check(&err) != TS_OK) {
        fprintf(stderr, "towstab: error: %s: --plot: %s\n", cmd, err.msg);
        return EXIT_BADINPUT;
    }
    if (p->units) {
        if (strcmp(p->units, "si") == 0 || strcmp(p->units, "SI") == 0)
            p->opts.units = TS_PLOT_SI;
        else if (strcmp(p->units, "imperial") == 0)
            p->opts.units = TS_PLOT_IMPERIAL;
        else {
            fprintf(stderr, "towstab: error: %s: --units: expected si or imperial, "
                            "got '%s'\n",
                    cmd, p->units);
            return EXIT_BADINPUT;
        }
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

int cli_plot_shape(const ts_system *sys, const double *pos, cli_shape *out)
{
    memset(out, 0, sizeof *out);
    out->link_upper = malloc(((size_t)sys->nlinks + 1) * sizeof(int));
    out->marks = malloc(((size_t)sys->nbodies + 1) * sizeof(int));
    if (!out->link_upper || !out->marks) {
        cli_plot_shape_free(out);
        return -1;
    }
    /* Link l joins its upper node to node l + 1 (ts_link.lower). */
    for (int l = 0; l < sys->nlinks; l++)
        out->link_upper[l] = sys->links[l].upper;
    int nmarks = 0;
    for (int b = 0; b < sys->nbodies; b++)
        if (sys->bodies[b].type == TS_BODY_SPHERE)
            out->marks[nmarks++] = ts_system_body_node(sys, b);
    ts_plot_shape *s = &out->shape;
    s->nnodes = sys->nnodes;
    s->pos = pos;
    s->link_upper = out->link_upper;
    s->nmarks = nmarks;
    s->marks = out->marks;
    /* doc/model.md section 1: the turn centre is at (0, V / Omega, 0). */
    s->turn_radius = sys->tow.turn_rate != 0
                         ? sys->tow.speed / sys->tow.turn_rate
                         : 0;
    s->label = out->label;
    return 0;
}

void cli_plot_shape_free(cli_shape *s)
{
    free(s->link_upper);
    free(s->marks);
    s->link_upper = s->marks = NULL;
}

void cli_plot_tow_label(const ts_system *sys, ts_plot_units u, char *buf,
                        size_t size)
{
    double v = ts_plot_convert(TS_PLOT_SPEED, u, sys->tow.speed);
    const char *vu = ts_plot_unit(TS_PLOT_SPEED, u);
    if (sys->tow.turn_rate == 0)
        snprintf(buf, size, "%.4g %s, straight", v, vu);
    else
        snprintf(buf, size, "%.4g %s, turn %.4g rad/s (%s)", v, vu,
                 fabs(sys->tow.turn_rate),
                 sys->tow.turn_rate > 0 ? "starboard" : "port");
}
