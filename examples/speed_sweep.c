/* speed_sweep.c: a program built on the towstab library alone, its public
 * headers and libtowstab found with pkg-config (README, "Using the
 * library"). It solves the steady shape of a scene's towed system at
 * several tow speeds and prints, for each, the depth of the first body
 * (or of the last free end when the scene has no body) and the top
 * tension: the whole force on the tow point (doc/model.md section 4).
 *
 *   cc speed_sweep.c $(pkg-config --cflags --libs towstab) -o speed_sweep
 *   ./speed_sweep SCENE SPEED...
 *
 * SPEED is a quantity as in a scene ("5 knot", "8.345 ft/s", 2.5 in m/s).
 * Output: a header line, then one line per speed: the speed (m/s), the
 * node's name and depth (m), the top tension (N), with 17 significant
 * digits. Exit status: 0 success, 1 an equilibrium that did not converge,
 * 2 bad input (usage, scene, speed).
 */
#include <stdio.h>
#include <stdlib.h>

#include "towstab/equilibrium.h"
#include "towstab/kernel.h"
#include "towstab/scene.h"
#include "towstab/system.h"
#include "towstab/units.h"

/* The node whose depth is reported: the first body's, else the lower end
 * of the last link (a free end). */
static int reported_node(const ts_system *sys, const char **name)
{
    if (sys->nbodies > 0) {
        *name = sys->bodies[0].name;
        return ts_system_body_node(sys, 0);
    }
    *name = sys->cables[sys->links[sys->nlinks - 1].cable].name;
    return sys->nnodes - 1;
}

/* Solve the equilibrium of sys at its tow speed and print one line.
 * Returns 0, or 1 when it failed (message on stderr). */
static int solve_one(const ts_system *sys)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(sys, &err);
    ts_equilibrium *eq = k ? ts_equilibrium_alloc(sys, &err) : NULL;
    int status = 1;
    if (eq && ts_equilibrium_solve(k, NULL, eq, &err) == TS_OK &&
        eq->converged) {
        const char *name;
        int node = reported_node(sys, &name);
        printf("%.17g %s %.17g %.17g\n", sys->tow.speed, name,
               eq->positions[3 * node + 2], eq->top_tension);
        status = 0;
    } else {
        fprintf(stderr, "speed_sweep: at %g m/s: %s\n", sys->tow.speed,
                err.code ? err.msg : "the equilibrium did not converge");
    }
    ts_equilibrium_free(eq);
    ts_kernel_free(k);
    return status;
}

int main(int argc, char **argv)
{
    if (argc < 3) {
        fprintf(stderr, "usage: speed_sweep SCENE SPEED...\n");
        return 2;
    }
    ts_err err = {0};
    ts_units *units = ts_units_alloc(&err);
    ts_scene *scene = units ? ts_scene_load(argv[1], units, &err) : NULL;
    if (!scene) {
        fprintf(stderr, "speed_sweep: %s\n", err.msg);
        ts_units_free(units);
        return 2;
    }
    ts_system *sys = scene->system;
    int status = 0;
    printf("# speed_m_s node depth_m top_tension_N (%s)\n", sys->name);
    for (int i = 2; i < argc && status != 2; i++) {
        double v;
        if (ts_units_parse(units, argv[i], "m/s", "SPEED", &v, &err) !=
                TS_OK ||
            !(v >= 0)) {
            fprintf(stderr, "speed_sweep: %s\n",
                    err.code ? err.msg : "SPEED: must be >= 0 m/s");
            status = 2;
            break;
        }
        /* A changed description is validated and rebuilt before use. */
        sys->tow.speed = v;
        if (ts_system_build(sys, &err) != TS_OK) {
            fprintf(stderr, "speed_sweep: %s\n", err.msg);
            status = 2;
            break;
        }
        if (solve_one(sys))
            status = 1;
    }
    ts_scene_free(scene);
    ts_units_free(units);
    return status;
}
