/* cli_plot.h: the --plot DIR and --units options of the subcommands, and
 * the conversions from analysis results to the plain arrays of
 * towstab/plot.h (tools only: the library never prints). */
#ifndef TOWSTAB_CLI_PLOT_H
#define TOWSTAB_CLI_PLOT_H

#include <stddef.h>

#include "towstab/equilibrium.h"
#include "towstab/plot.h"
#include "towstab/system.h"
#include "towstab/units.h"

/* What a command was asked to draw. */
typedef struct cli_plot {
    const char *dir;   /* --plot DIR, NULL for no pictures */
    const char *units; /* --units TEXT, NULL for SI (tables, CSV and
                          pictures: cli_display_begin) */
    ts_plot_opts opts; /* filled by cli_plot_begin; opts.display is set
                          by the caller to its display */
    int made;          /* cli_plot_begin made DIR (it did not exist) */
} cli_plot;

/* Check --plot before any analysis runs: that pictures can be drawn
 * (towstab built with PLplot, cairo driver present) and that DIR is (or
 * can be made) a writable directory. Prints "towstab CMD: ..." and
 * returns the exit status on failure (2 for bad input or a build without
 * PLplot, 1 when DIR cannot be created); 0 when there is nothing to draw
 * or all is well. */
int cli_plot_begin(cli_plot *p, const char *cmd);

/* After a refused or failed run: remove DIR again when cli_plot_begin
 * made it and nothing was drawn into it (an empty directory). */
void cli_plot_abandon(cli_plot *p);

/* Print "wrote DIR/NAME.png and DIR/NAME.svg" (the formats drawn). */
void cli_plot_wrote(const cli_plot *p, const char *name);
/* The display units of --units `spec` (NULL: SI) into d
 * (ts_display_parse: si, imperial, QUANTITY=UNIT items). Prints and
 * returns EXIT_BADINPUT for a bad spec, else 0. */
int cli_display_begin(const ts_units *units, const char *spec,
                      ts_display *d);

/* A cable shape of `sys` at node positions pos[3 nnodes] (m, M frame),
 * for ts_plot_shapes / ts_plot_mode_shapes: links as in sys, spheres
 * marked, cylinder towfish drawn, the ship's turning circle R = V /
 * Omega when turning. Owns its
 * arrays: release with cli_plot_shape_free. Returns 0, or -1 when out of
 * memory. */
typedef struct cli_shape {
    ts_plot_shape shape;
    int *link_upper; /* [nlinks] */
    int *marks;      /* [nbodies] */
    ts_plot_cylinder *cylinders; /* [nbodies] */
    char label[192];
    ts_plot_outline *outlines; /* [nbodies]: vehicles with their attitude */
} cli_shape;

int cli_plot_shape(const ts_system *sys, const ts_equilibrium *eq,
                   const double *pos, cli_shape *out);
void cli_plot_shape_free(cli_shape *s);

/* Add vehicle body `b` of sys to the shape, drawn with attitude R (body
 * to M, row-major) about the shape's node of the body (its attach point),
 * its surfaces at deflections delta[ncomponents] (NULL: the open-loop
 * ones). Returns 0, or -1 when out of memory. */
int cli_plot_add_vehicle(cli_shape *s, const ts_system *sys, int b,
                         const double R[9], const double *delta);

/* The vehicles of an equilibrium (eq->vehicles), added to s. */
int cli_plot_add_vehicles(cli_shape *s, const ts_system *sys,
                          const ts_equilibrium *eq);

/* "5 knot, straight" or "1.48 knot, turn 0.5 rad/s (starboard)": the tow
 * of `sys` as a legend label: the speed and turn rate as the user wrote
 * them (speed_text, turn_text; NULL or "": in the display units d). */
void cli_plot_tow_label(const ts_system *sys, const ts_equilibrium *eq,
                        const char *speed_text, const char *turn_text,
                        const ts_display *d,
                        char *buf, size_t size);

#endif
