/* elastic_table: the EA convergence table of doc/elastic.md.
 *
 * Kamman example 1 (bench_common.h; examples/kamman_ex1_submerged.yaml)
 * at 20 links, rigid and with an elastic cable of EA = 1e4 .. 1e10 N
 * (Cv = 0: with damping the axial modes are overdamped at small EA and
 * their frequency says nothing about sqrt(EA)). For each EA:
 *  - equilibrium, straight tow and a turn of radius 2 L: the largest node
 *    position difference from the rigid shape over the cable length, and
 *    (turn) the relative difference of the top tension;
 *  - modes (linearized about the straight equilibrium, LAPACK): the
 *    largest relative distance from each of the rigid model's 10 lowest
 *    eigenvalues to the nearest elastic one, and the highest frequency with
 *    its ratio to sqrt(EA) and to the fixed-free spring-mass chain,
 *    (1/pi) sqrt(EA / (l m)) cos(pi / (2N + 1)).
 * Then the log-log slopes over EA = 1e6 .. 1e10 N. Prints a Markdown
 * table. Build and run from the project root:
 *     ninja -C build test/elastic_table && build/test/elastic_table */
#include "bench_common.h"
#include "towstab/eigen.h"
#include "towstab/equilibrium.h"
#include "towstab/kernel.h"
#include "towstab/linearize.h"

#define NLINKS 20
#define NLOW 10

static ts_system *ex1(double ea, double turn)
{
    ts_system *s = bench_kamman_ex1(NLINKS, turn);
    if (s && ea > 0) {
        s->cables[0].ea = ea;
        if (ts_system_build(s, NULL) != TS_OK) {
            ts_system_free(s);
            return NULL;
        }
    }
    return s;
}

/* Equilibrium (and, when eig is not NULL, all modes) of s. */
static ts_equilibrium *analyse(const ts_system *s, ts_eigen **eig)
{
    ts_err err = {0};
    ts_kernel *k = ts_kernel_alloc(s, &err);
    ts_equilibrium *eq = ts_equilibrium_alloc(s, &err);
    int rc = k && eq ? ts_equilibrium_solve(k, NULL, eq, &err) : TS_ENOMEM;
    if (rc == TS_OK && eig) {
        *eig = NULL;
        ts_linear *lin = ts_linear_alloc(k, &err);
        ts_linearize_opts lo;
        ts_linearize_opts_default(&lo);
        ts_eigen_opts eo;
        ts_eigen_opts_default(&eo);
        eo.method = TS_EIG_LAPACK;
        rc = lin ? ts_linearize_equilibrium(k, eq, &lo, lin, &err)
                 : TS_ENOMEM;
        if (rc == TS_OK)
            rc = ts_eigen_solve(lin, &eo, eig, &err);
        ts_linear_free(lin);
    }
    if (rc != TS_OK)
        fprintf(stderr, "elastic_table: %s\n", err.msg);
    ts_kernel_free(k);
    if (rc != TS_OK) {
        ts_equilibrium_free(eq);
        return NULL;
    }
    return eq;
}

static double max_diff(const ts_equilibrium *a, const ts_equilibrium *b)
{
    double d = 0;
    for (int i = 0; i < 3 * a->nnodes; i++)
        d = fmax(d, fabs(a->positions[i] - b->positions[i]));
    return d;
}

static double match_modes(const ts_eigen *ref, const ts_eigen *e)
{
    double worst = 0;
    for (int i = 0; i < NLOW && i < ref->nmodes; i++) {
        double best = INFINITY;
        for (int j = 0; j < e->nmodes; j++)
            best = fmin(best, hypot(e->modes[j].re - ref->modes[i].re,
                                    e->modes[j].im - ref->modes[i].im));
        worst = fmax(worst, best / hypot(ref->modes[i].re, ref->modes[i].im));
    }
    return worst;
}

static double slope(const double *x, const double *y, int n)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    for (int i = 0; i < n; i++) {
        double a = log(x[i]), b = log(y[i]);
        sx += a;
        sy += b;
        sxx += a * a;
        sxy += a * b;
    }
    return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

int main(void)
{
    static const double eas[] = {1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10};
    enum { NEA = 7, FIRST_FIT = 2 };
    ts_system *r0 = ex1(0, 0);
    double V = r0->tow.speed, L = r0->cables[0].length;
    double turn = V / (2 * L);
    ts_system *rt = ex1(0, turn);
    ts_eigen *er = NULL;
    ts_equilibrium *eq0 = analyse(r0, &er), *eqt = analyse(rt, NULL);
    if (!eq0 || !eqt || !er)
        return 1;
    const double l = r0->links[0].length, m = r0->links[0].mass;
    double dstraight[NEA], dturn[NEA], dten[NEA], dmode[NEA], fhi[NEA];
    printf("Kamman example 1, %d links, Cv = 0; rigid: top tension %.6f N "
           "straight, %.6f N in the turn (radius 2 L, %.6f rad/s)\n\n",
           NLINKS, eq0->top_tension, eqt->top_tension, turn);
    printf("| EA [N] | straight: max dr / L | turn: max dr / L | turn: top "
           "tension | %d lowest modes | highest mode [Hz] | / sqrt(EA) | "
           "/ chain |\n", NLOW);
    printf("|---:|---:|---:|---:|---:|---:|---:|---:|\n");
    int bad = 0;
    for (int i = 0; i < NEA; i++) {
        ts_system *s0 = ex1(eas[i], 0), *st = ex1(eas[i], turn);
        ts_eigen *ee = NULL;
        ts_equilibrium *a = analyse(s0, &ee), *b = analyse(st, NULL);
        if (!a || !b || !ee) {
            bad = 1;
            continue;
        }
        dstraight[i] = max_diff(a, eq0) / L;
        dturn[i] = max_diff(b, eqt) / L;
        dten[i] = fabs(b->top_tension - eqt->top_tension) / eqt->top_tension;
        dmode[i] = match_modes(er, ee);
        fhi[i] = 0;
        for (int j = 0; j < ee->nmodes; j++)
            fhi[i] = fmax(fhi[i], ee->modes[j].freq_hz);
        double chain = sqrt(eas[i] / (l * m)) *
                       cos(M_PI / (2 * NLINKS + 1)) / M_PI;
        printf("| %.0e | %.3e | %.3e | %.3e | %.3e | %.6g | %.6f | %.5f |\n",
               eas[i], dstraight[i], dturn[i], dten[i], dmode[i], fhi[i],
               fhi[i] / sqrt(eas[i]), fhi[i] / chain);
        ts_eigen_free(ee);
        ts_equilibrium_free(a);
        ts_equilibrium_free(b);
        ts_system_free(s0);
        ts_system_free(st);
    }
    if (bad)
        return 1;
    int n = NEA - FIRST_FIT;
    printf("\nlog-log slopes over EA = %.0e .. %.0e N: straight shape %.4f, "
           "turn shape %.4f, turn top tension %.4f, low modes %.4f, highest "
           "frequency %.5f\n", eas[FIRST_FIT], eas[NEA - 1],
           slope(eas + FIRST_FIT, dstraight + FIRST_FIT, n),
           slope(eas + FIRST_FIT, dturn + FIRST_FIT, n),
           slope(eas + FIRST_FIT, dten + FIRST_FIT, n),
           slope(eas + FIRST_FIT, dmode + FIRST_FIT, n),
           slope(eas + FIRST_FIT, fhi + FIRST_FIT, n));
    ts_eigen_free(er);
    ts_equilibrium_free(eq0);
    ts_equilibrium_free(eqt);
    ts_system_free(r0);
    ts_system_free(rt);
    return 0;
}
