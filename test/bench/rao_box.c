/* rao_box.c: writes examples/ship_rao.csv, the heave and pitch RAOs of a
 * box-shaped 60 m ship at 4 knots (doc/seastate.md, section 2, where the
 * model is derived). Not a test: it prints the table.
 *
 *   build/test/rao_box > examples/ship_rao.csv
 *
 * The model (after Jensen, Mansour & Olsen 2004, Ocean Engineering 31,
 * 61-85, whose closed forms have the same structure): a box of length L,
 * beam B and draught T, uniformly loaded, in a regular wave of amplitude a,
 * frequency w and heading beta (180 deg head seas) at speed U.
 *   k = w^2/g, k_x = k cos(beta), k_y = k sin(beta),
 *   w_e = w - k U cos(beta), k_w = w_e^2 / g;
 * Froude-Krylov pressure on the bottom, decayed by exp(-k T) and averaged
 * over the beam (sinc(k_y B/2)), gives the quasi-static heave (up) and
 * pitch (bow up) per metre of wave amplitude
 *   heave_qs = e sinc(k_x L/2),
 *   pitch_qs = -i e (12 / L^3) 2 [sin(k_x L/2) - (k_x L/2) cos(k_x L/2)]
 *              / k_x^2,     e = exp(-k T) sinc(k_y B/2);
 * with the added mass equal to the displaced mass and the two-dimensional
 * radiation damping of the box's section (radiated wave amplitude ratio
 * A = 2 sin(k_w B/2) exp(-k_w T)), heave and pitch share the dynamic
 * factor
 *   D = 1 / (1 - 2 k_w T + i A^2 / (k_w B)).
 * RAOs in M (z down, leads over the crest at midship on the waterline):
 * heave = -heave_qs D (m/m), pitch = pitch_qs D (rad/m, written in
 * deg/m). Surge, sway, roll and yaw are not modelled (zero): the table is
 * for head and bow seas, where they are small.
 */
#include <complex.h>
#include <math.h>
#include <stdio.h>

#define G 9.80665
#define SHIP_L 60.0      /* m */
#define SHIP_B 12.0      /* m: beam times block coefficient, 18.5 x 0.65 */
#define SHIP_T 4.5       /* m */
#define SHIP_U 2.0578    /* m/s: 4 knots */

static double sinc(double x)
{
    return fabs(x) < 1e-8 ? 1.0 - x * x / 6.0 : sin(x) / x;
}

int main(void)
{
    printf("# Heave and pitch RAOs of a box-shaped ship: L = %g m, B = %g "
           "m (beam\n# 18.5 m times block coefficient 0.65), T = %g m, "
           "at 4 knots, from the\n# closed-form model of doc/seastate.md "
           "section 2 (Froude-Krylov force\n# on the bottom, added mass = "
           "displaced mass, 2-D box radiation damping),\n# written by "
           "test/bench/rao_box.c. Reference point: midship on the\n# "
           "waterline. Illustrative, not a real ship: no surge, sway, roll "
           "or yaw.\n", SHIP_L, SHIP_B, SHIP_T);
    printf("axes: z-down\nphase: lead\n");
    printf("omega [rad/s], heading [deg], heave amp [m/m], heave phase "
           "[deg], pitch amp [deg/m], pitch phase [deg]\n");
    for (int h = 120; h <= 180; h += 15) {
        double beta = h * M_PI / 180.0;
        for (int i = 0; i <= 46; i++) {
            double w = 0.2 + 0.05 * i;
            double k = w * w / G, kx = k * cos(beta), ky = k * sin(beta);
            double we = w - k * SHIP_U * cos(beta), kw = we * we / G;
            double e = exp(-k * SHIP_T) * sinc(ky * SHIP_B / 2);
            double x = kx * SHIP_L / 2;
            double heave_qs = e * sinc(x);
            double s = fabs(kx) < 1e-8
                           ? kx * SHIP_L * SHIP_L * SHIP_L / 12.0
                           : 2.0 * (sin(x) - x * cos(x)) / (kx * kx);
            double complex pitch_qs = -I * e * 12.0 / pow(SHIP_L, 3) * s;
            double A = 2.0 * sin(kw * SHIP_B / 2) * exp(-kw * SHIP_T);
            double complex D =
                1.0 / (1.0 - 2.0 * kw * SHIP_T +
                       I * (kw > 0 ? A * A / (kw * SHIP_B) : 0.0));
            double complex heave = -heave_qs * D, pitch = pitch_qs * D;
            printf("%.2f, %d, %.6f, %.3f, %.6f, %.3f\n", w, h, cabs(heave),
                   carg(heave) * 180 / M_PI, cabs(pitch) * 180 / M_PI,
                   carg(pitch) * 180 / M_PI);
        }
    }
    return 0;
}
