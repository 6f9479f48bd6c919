/* kernel.c: f(y, u) of the rigid-link tree (doc/model.md sections 1-4, 8).
 *
 * Algorithm, O(nlinks) per call:
 *  1. Kinematics, tow point to free ends: link directions n, e1, e2 and
 *     direction rates from the angles; node positions r_k = r_p + l n_k and
 *     velocities relative to M.
 *  2. Loads: weight, buoyancy, drag of every link (half to each end),
 *     spheres, bending joints (forces.h); nodal 3x3 mass matrices with the
 *     normal added mass of the adjacent links (a scalar when the system has
 *     no added mass); the frame part afr of each node's acceleration.
 *  3. Tensions. Node k obeys M_k a_k = Q_k - t_k n_k + sum_c t_c n_c and each
 *     link the rigidity condition n_k.(a_k - a_p) = n_k.(afr_k - afr_p)
 *     - l |n_k'|^2. From the free ends up, each node's children are
 *     eliminated: a child c contributes t_c = beta_c - n_c.a_k / D_c, so
 *     node k sees the articulated mass Mh_k = M_k + sum_c n_c n_c^T / D_c and
 *     load Fh_k = Q_k + sum_c beta_c n_c, with D_k = n_k.Mh_k^-1 n_k and
 *     beta_k = (n_k.Mh_k^-1 Fh_k - rhs_k) / D_k. Going down from the tow
 *     point (a_0 prescribed) gives t_k = beta_k - n_k.a_p / D_k and
 *     a_k = Mh_k^-1 (Fh_k - t_k n_k). This is the elimination of the
 *     symmetric positive definite tension system G M^-1 G^T t = b, leaves
 *     first, without fill-in.
 *  4. Angles: r''_k = a_k - afr_k, n'' = (r''_k - r''_p) / l and
 *     t1'' = (e1.n'' + 2 s2 t1' t2') / c2, t2'' = e2.n'' - c2 s2 t1'^2.
 *
 * Vehicles (doc/kernel.md, "Vehicles"; lib/vehicle.h for their physics):
 * a vehicle hangs on a spherical joint at its node i, the lower end of the
 * link `in` above it, and adds its three 1-2-3 angles to q. Its body
 * equations about the attach point A in body axes are M6 (a_A, alpha) =
 * G + (F_j, 0) + the child cables that start at its points P (each a
 * rank-one update J_P^T n n^T J_P / D like a child link of a node, J_P =
 * [I, -S(rho_P)]). Eliminating the six body accelerations leaves a_A =
 * W F_j + a_free with W = J M6^-1 J^T (J = [I 0]), so the node sees
 * the articulated mass M_i + W^-1 and the load Q_i + W^-1 a_free: the
 * tree recursion is unchanged and each vehicle costs O(1). Going down,
 * F_j = W^-1 (a_A - a_free) gives the body's accelerations and the
 * accelerations of the points its child cables start from. Controller
 * states (integrators, actuators) follow q' in y.
 *
 * One module, though long: f(y, u) is one recursion over the tree (down
 * for the kinematics, up for the articulated masses, down again for the
 * accelerations) whose rigid, elastic, bending and vehicle parts share
 * every per-node and per-link array of one pass.
 */
#include "towstab/kernel.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "forces.h"
#include "kernel_impl.h"
#include "vec3.h"
#include "vehicle.h"

/* Outputs: per vehicle its 4 measurements, then its loops' outputs. */
#define OUT_MEASURES 4

/* One vehicle's coupling data. */
typedef struct veh {
    int body, node, qoff;     /* body index, its node, offset in q */
    const ts_vehicle *d;
    double mass;
    double chart[9];          /* body chart to M: R = chart R123(theta) */
    int charted;
    tsi_vehicle_ws *ws;
    tsi_vehicle_state st;
    double M6[36];            /* spatial inertia about A, body axes, with
                                 the point masses of child cables' ends */
    double M6h[36], L6[36];   /* with the child cables eliminated; its
                                 Cholesky factor */
    double G[6];              /* known generalised force about A */
    double Winv[6];           /* W^-1 in M (sym3) */
    double afree[3];          /* a_free in M */
    double a6[6];             /* (a_A, alpha), body axes */
    double alpha_m[3];        /* alpha in M */
    double Fj[3];             /* joint force on the body, M */
    /* Controller layout: -1 where there is none. */
    int xi_off[TS_VEHICLE_MAX_LOOPS];      /* integrator, offset in c */
    int act_off[TS_VEHICLE_MAX_COMPONENTS];/* actuator, offset in c */
    int in_surf[TS_VEHICLE_MAX_COMPONENTS];/* input index */
    int in_loop[TS_VEHICLE_MAX_LOOPS];     /* input index (output) */
    int in_sp[TS_VEHICLE_MAX_LOOPS];       /* input index (set point) */
    double sp[TS_VEHICLE_MAX_LOOPS];       /* set points in force */
    int mode[TS_VEHICLE_MAX_LOOPS];        /* TS_LOOP_* */
    double frozen[TS_VEHICLE_MAX_LOOPS];   /* frozen outputs */
    double meas[4], rate[4];
    double out[TS_VEHICLE_MAX_LOOPS];
    double delta[TS_VEHICLE_MAX_COMPONENTS];
    double xi_dot[TS_VEHICLE_MAX_LOOPS];
    double act_dot[TS_VEHICLE_MAX_COMPONENTS];
    double lever;             /* tsi_vehicle_lever, at least 1 m */
    /* The towing vehicle, root of the tree (doc/towing-vehicle.md): its
     * attach point A is node 0, whose position in M is 3 more
     * coordinates after the angles (qoff + 3); no joint (Fj = 0). */
    int root;
    int in_prop;              /* its first input: thrust (N), then the
                                 external force (N) and moment (N m) in
                                 body axes, TSI_NPROP in all; -1 */
    int in_spd;               /* a speed controller's set-speed input
                                 (m/s, added to its set speed), after
                                 the TSI_NPROP; -1 */
    double thrust_bias;       /* the speed controller's bias, N */
    double turn_delta;        /* the deflection added to the turn surface
                                 (ts_tow.turn_surface), rad */
    double thrust;            /* thrust at the last evaluation, N */
    int spd_off;              /* a PI speed controller's integrator, offset
                                 in c (0: the first state); -1 */
    double spd_dot;           /* its rate at the last evaluation, m/s */
    /* A surface ship (ts_tow.dof 3): only its yaw (at qoff) and the tow
     * point's x, y (qoff + 1, + 2) are coordinates; roll and pitch are 0
     * and the tow point's depth is the scene's. held: the hull's
     * hydrostatic reaction that holds them, at the last evaluation: the
     * vertical force on the hull at A (N, down > 0) and the roll and
     * pitch moments about A (N m, body axes). */
    int dof;                  /* 6, or 3; 0 for a towed vehicle */
    double held[3];
    /* The towing vehicle: the prescribed acceleration (body axes) of the
     * points its cables start from relative to the body, the tow-point
     * inputs' (wave-induced motion, doc/towing-vehicle.md section 8):
     * shift_a + shift_al x p at the point p (body axes from O); 0 for a
     * towed vehicle. */
    double shift_a[3], shift_al[3];
} veh;

/* Inputs of a towing vehicle: thrust, force x y z, moment x y z. */
#define TSI_NPROP 7

struct ts_kernel {
    const ts_system *sys;
    int nl, nn;
    int nq;            /* generalised coordinates: 2 per rigid link, 3 per
                          elastic link, then 3 per vehicle */
    int nql;           /* the links' share of nq */
    int nc;            /* controller states, after q' in y */
    int nin;           /* inputs: TS_NINPUT, the vehicles' control
                          surfaces, their loops */
    double *uzero;     /* [nin] zero input */
    int nv;            /* vehicles */
    veh *veh;          /* [nv] */
    int root;          /* the towing vehicle's index in veh, -1: the tow
                          point is prescribed */
    int *node_veh;     /* [nn] vehicle at the node, -1 */
    /* Links that start at a point P of a vehicle (up_body >= 0): */
    double *ur, *urd;  /* [3 nl] P's position and velocity rel. to M */
    double *uafr, *ua; /* [3 nl] P's frame and inertial acceleration */
    double *uQ;        /* [3 nl] loads at P (half the link's, bending) */
    double *uM;        /* [6 nl] mass at P (half the link's, its normal
                          added mass), sym3 in M */
    int *off;          /* [nl] offset of link l's coordinates in q */
    ts_frame frame;
    double bend_scale; /* multiplies every EI (continuation), default 1 */
    int steady;        /* 1: actuators without rate limits (steady states) */

    double *chart;     /* [9 nl] row-major rotation per link */
    char *charted;     /* [nl] 1 when chart is not the identity */

    /* Per link. */
    double *n, *e1, *e2, *nd; /* [3 nl] direction, chart axes, rate */
    double *c2, *s2;          /* [nl] */
    double *sub;              /* [nl] submerged fraction */
    double *t;                /* [nl] tension */
    double *strain;           /* [nl] strain e of an elastic link (0 for a
                                 rigid one): its length is l (1 + e) */
    double *D, *beta;         /* [nl] articulated elimination */
    /* Per node. */
    double *r, *rd;           /* [3 nn] position, velocity relative to M */
    double *Q;                /* [3 nn] external load */
    double *M;                /* [6 nn] nodal mass matrix (sym) */
    double *afr;              /* [3 nn] frame part of acceleration */
    double *Mh;               /* [6 nn] articulated mass */
    double *Fh;               /* [3 nn] articulated load */
    double *g, *w;            /* [3 nn] Mh^-1 Fh, Mh^-1 n */
    double *a;                /* [3 nn] inertial acceleration */
    double *rdd;              /* [3 nn] acceleration relative to M */
    double tow_acc[3];        /* a prescribed tow point's acceleration
                                 from the tow inputs, M */
};

static void *zalloc(size_t n, size_t size, int *fail)
{
    void *p = calloc(n > 0 ? n : 1, size);
    if (!p)
        *fail = 1;
    return p;
}

/* Offsets of the controller states (integrators of loops that are not
 * frozen, actuators of surfaces with a time constant) and of the inputs
 * (every control surface, every loop), from the loops' modes. */
static int layout_controls(ts_kernel *k, ts_err *err)
{
    k->nc = 0;
    k->nin = TS_NINPUT;
    /* A PI speed controller's integrator first: no loop mode moves it.
     * Its vehicle's own controller states follow it, so that each
     * vehicle's states are one block (the sparse model's local blocks,
     * lib/descriptor.h); the other vehicles' follow in their order. */
    int first = -1;
    for (int v = 0; v < k->nv; v++) {
        veh *V = &k->veh[v];
        const ts_propulsion *p = &V->d->propulsion;
        V->spd_off = V->root && p->type == TS_PROP_SPEED && p->ki > 0
                         ? k->nc++
                         : -1;
        if (V->spd_off >= 0)
            first = v;
    }
    for (int i = -1; i < k->nv; i++) {
        int v = i < 0 ? first : i;
        if (v < 0 || (i >= 0 && v == first))
            continue;
        veh *V = &k->veh[v];
        const ts_vehicle *d = V->d;
        for (int l = 0; l < TS_VEHICLE_MAX_LOOPS; l++) {
            V->xi_off[l] = -1;
            if (l < d->nloops && d->loop[l].ki != 0 &&
                V->mode[l] != TS_LOOP_OPEN)
                V->xi_off[l] = k->nc++;
        }
        for (int c = 0; c < TS_VEHICLE_MAX_COMPONENTS; c++) {
            V->act_off[c] = -1;
            if (c < d->ncomponents && d->component[c].control &&
                d->component[c].time_constant > 0)
                V->act_off[c] = k->nc++;
        }
    }
    /* The inputs, each vehicle's in its order. */
    for (int v = 0; v < k->nv; v++) {
        veh *V = &k->veh[v];
        const ts_vehicle *d = V->d;
        for (int l = 0; l < TS_VEHICLE_MAX_LOOPS; l++)
            V->in_loop[l] = V->in_sp[l] = -1;
        for (int c = 0; c < TS_VEHICLE_MAX_COMPONENTS; c++) {
            V->in_surf[c] = -1;
            if (c < d->ncomponents && d->component[c].control)
                V->in_surf[c] = k->nin++;
        }
        for (int l = 0; l < d->nloops; l++) {
            V->in_loop[l] = k->nin++;
            V->in_sp[l] = k->nin++;
        }
        V->in_prop = V->in_spd = -1;
        if (V->root) {
            V->in_prop = k->nin;
            k->nin += TSI_NPROP;
            if (d->propulsion.type == TS_PROP_SPEED)
                V->in_spd = k->nin++;
        }
    }
    free(k->uzero);
    k->uzero = calloc((size_t)k->nin, sizeof(double));
    if (!k->uzero)
        return ts_fail(err, TS_ENOMEM, "kernel: out of memory");
    return TS_OK;
}

ts_kernel *ts_kernel_alloc(const ts_system *sys, ts_err *err)
{
    if (!sys || !sys->links) {
        ts_fail(err, TS_EINVAL, "ts_kernel_alloc: the system is not built");
        return NULL;
    }
    ts_kernel *k = calloc(1, sizeof *k);
    if (!k) {
        ts_fail(err, TS_ENOMEM, "ts_kernel_alloc: out of memory");
        return NULL;
    }
    int nl = sys->nlinks, nn = sys->nnodes, fail = 0;
    size_t snl = (size_t)nl, snn = (size_t)nn;
    k->sys = sys;
    k->nl = nl;
    k->nn = nn;
    k->off = zalloc(snl, sizeof(int), &fail);
    k->chart = zalloc(9 * snl, sizeof(double), &fail);
    k->charted = zalloc(snl, 1, &fail);
    k->n = zalloc(3 * snl, sizeof(double), &fail);
    k->e1 = zalloc(3 * snl, sizeof(double), &fail);
    k->e2 = zalloc(3 * snl, sizeof(double), &fail);
    k->nd = zalloc(3 * snl, sizeof(double), &fail);
    k->c2 = zalloc(snl, sizeof(double), &fail);
    k->s2 = zalloc(snl, sizeof(double), &fail);
    k->sub = zalloc(snl, sizeof(double), &fail);
    k->t = zalloc(snl, sizeof(double), &fail);
    k->strain = zalloc(snl, sizeof(double), &fail);
    k->D = zalloc(snl, sizeof(double), &fail);
    k->beta = zalloc(snl, sizeof(double), &fail);
    k->r = zalloc(3 * snn, sizeof(double), &fail);
    k->rd = zalloc(3 * snn, sizeof(double), &fail);
    k->Q = zalloc(3 * snn, sizeof(double), &fail);
    k->M = zalloc(6 * snn, sizeof(double), &fail);
    k->afr = zalloc(3 * snn, sizeof(double), &fail);
    k->Mh = zalloc(6 * snn, sizeof(double), &fail);
    k->Fh = zalloc(3 * snn, sizeof(double), &fail);
    k->g = zalloc(3 * snn, sizeof(double), &fail);
    k->w = zalloc(3 * snn, sizeof(double), &fail);
    k->a = zalloc(3 * snn, sizeof(double), &fail);
    k->rdd = zalloc(3 * snn, sizeof(double), &fail);
    k->node_veh = zalloc(snn, sizeof(int), &fail);
    k->nv = sys->nvehicles;
    k->veh = zalloc((size_t)k->nv, sizeof(veh), &fail);
    if (k->nv > 0) {
        k->ur = zalloc(3 * snl, sizeof(double), &fail);
        k->urd = zalloc(3 * snl, sizeof(double), &fail);
        k->uafr = zalloc(3 * snl, sizeof(double), &fail);
        k->ua = zalloc(3 * snl, sizeof(double), &fail);
        k->uQ = zalloc(3 * snl, sizeof(double), &fail);
        k->uM = zalloc(6 * snl, sizeof(double), &fail);
    }
    if (fail) {
        ts_kernel_free(k);
        ts_fail_nomem(err, 8.0 * 60.0 * nl, "fewer links", "kernel: out of "
                      "memory for %d links", nl);
        return NULL;
    }
    for (int l = 0; l < nl; l++) {
        double *R = k->chart + 9 * l;
        R[0] = R[4] = R[8] = 1.0;
        k->off[l] = k->nq;
        k->nq += sys->links[l].elastic ? 3 : 2;
    }
    k->nql = k->nq;
    for (int i = 0; i < nn; i++)
        k->node_veh[i] = -1;
    k->root = -1;
    for (int b = 0, v = 0; b < sys->nbodies; b++) {
        if (sys->bodies[b].type != TS_BODY_VEHICLE)
            continue;
        veh *V = &k->veh[v];
        V->body = b;
        V->node = ts_system_body_node(sys, b);
        V->d = sys->bodies[b].vehicle;
        V->mass = sys->bodies[b].mass;
        V->chart[0] = V->chart[4] = V->chart[8] = 1.0;
        V->qoff = k->nq;
        k->nq += 3;
        if (b == sys->tow.vehicle) {
            V->root = 1;
            V->dof = sys->tow.dof == 3 ? 3 : 6;
            k->root = v;
            /* The position of A (node 0) in M; a surface ship keeps only
             * its yaw of the angles and x, y of the position. */
            k->nq += V->dof == 3 ? 0 : 3;
            V->thrust_bias = V->d->propulsion.thrust;
        }
        /* A body whose points all sit at A has no lever: its unbalanced
         * moment is compared per metre. */
        V->lever = fmax(tsi_vehicle_lever(V->d), 1.0);
        for (int l = 0; l < TS_VEHICLE_MAX_LOOPS; l++) {
            V->mode[l] = TS_LOOP_CLOSED;
            V->sp[l] = l < V->d->nloops ? V->d->loop[l].setpoint : 0.0;
        }
        k->node_veh[V->node] = v;
        V->ws = tsi_vehicle_ws_alloc(V->d, err);
        if (!V->ws) {
            ts_kernel_free(k);
            return NULL;
        }
        v++;
    }
    if (layout_controls(k, err) != TS_OK) {
        ts_kernel_free(k);
        return NULL;
    }
    k->bend_scale = 1.0;
    k->frame.speed = sys->tow.speed;
    k->frame.turn_rate = sys->tow.turn_rate;
    memcpy(k->frame.current, sys->env.current, sizeof k->frame.current);
    return k;
}

void ts_kernel_free(ts_kernel *k)
{
    if (!k)
        return;
    free(k->off);
    free(k->chart);
    free(k->charted);
    free(k->n);
    free(k->e1);
    free(k->e2);
    free(k->nd);
    free(k->c2);
    free(k->s2);
    free(k->sub);
    free(k->t);
    free(k->strain);
    free(k->D);
    free(k->beta);
    free(k->r);
    free(k->rd);
    free(k->Q);
    free(k->M);
    free(k->afr);
    free(k->Mh);
    free(k->Fh);
    free(k->g);
    free(k->w);
    free(k->a);
    free(k->rdd);
    for (int v = 0; k->veh && v < k->nv; v++)
        tsi_vehicle_ws_free(k->veh[v].ws);
    free(k->veh);
    free(k->node_veh);
    free(k->ur);
    free(k->urd);
    free(k->uafr);
    free(k->ua);
    free(k->uQ);
    free(k->uM);
    free(k->uzero);
    free(k);
}

ts_kernel *ts_kernel_clone(const ts_kernel *k, ts_err *err)
{
    ts_kernel *c = ts_kernel_alloc(k->sys, err);
    if (!c)
        return NULL;
    c->frame = k->frame;
    c->bend_scale = k->bend_scale;
    c->steady = k->steady;
    memcpy(c->chart, k->chart, 9 * (size_t)k->nl * sizeof(double));
    memcpy(c->charted, k->charted, (size_t)k->nl);
    for (int v = 0; v < k->nv; v++) {
        memcpy(c->veh[v].chart, k->veh[v].chart, sizeof k->veh[v].chart);
        c->veh[v].charted = k->veh[v].charted;
        memcpy(c->veh[v].mode, k->veh[v].mode, sizeof k->veh[v].mode);
        memcpy(c->veh[v].frozen, k->veh[v].frozen, sizeof k->veh[v].frozen);
        memcpy(c->veh[v].sp, k->veh[v].sp, sizeof k->veh[v].sp);
        c->veh[v].thrust_bias = k->veh[v].thrust_bias;
        c->veh[v].turn_delta = k->veh[v].turn_delta;
    }
    if (layout_controls(c, err) != TS_OK) {
        ts_kernel_free(c);
        return NULL;
    }
    return c;
}

const ts_system *ts_kernel_system(const ts_kernel *k) { return k->sys; }
int ts_kernel_nq(const ts_kernel *k) { return k->nq; }
int ts_kernel_nstate(const ts_kernel *k) { return 2 * k->nq + k->nc; }
int ts_kernel_ncontrol(const ts_kernel *k) { return k->nc; }
int ts_kernel_link_offset(const ts_kernel *k, int link) { return k->off[link]; }
int ts_kernel_ninput(const ts_kernel *k) { return k->nin; }
int ts_kernel_nvehicles(const ts_kernel *k) { return k->nv; }

int ts_kernel_set_loop_mode(ts_kernel *k, int v, int loop, int mode,
                            double frozen, ts_err *err)
{
    if (v < 0 || v >= k->nv || loop < 0 || loop >= k->veh[v].d->nloops)
        return ts_fail(err, TS_EINVAL, "kernel: no loop %d of vehicle %d",
                       loop, v);
    if (mode != TS_LOOP_CLOSED && mode != TS_LOOP_OPEN &&
        mode != TS_LOOP_BROKEN)
        return ts_fail(err, TS_EINVAL, "kernel: loop mode %d", mode);
    k->veh[v].mode[loop] = mode;
    k->veh[v].frozen[loop] = frozen;
    return layout_controls(k, err);
}

int ts_kernel_loop_mode(const ts_kernel *k, int v, int loop)
{
    return k->veh[v].mode[loop];
}

void ts_kernel_set_setpoint(ts_kernel *k, int v, int loop, double value)
{
    k->veh[v].sp[loop] = value;
}

double ts_kernel_setpoint(const ts_kernel *k, int v, int loop)
{
    return k->veh[v].sp[loop];
}

void ts_kernel_set_steady(ts_kernel *k, int steady) { k->steady = steady; }

void ts_kernel_get_controls(const ts_kernel *k, int v, const double y[],
                            double xi[], double act[])
{
    const veh *V = &k->veh[v];
    const double *c = y + 2 * k->nq;
    for (int l = 0; l < V->d->nloops; l++)
        xi[l] = V->xi_off[l] >= 0 ? c[V->xi_off[l]] : 0.0;
    for (int j = 0; j < V->d->ncomponents; j++)
        act[j] = V->act_off[j] >= 0 ? c[V->act_off[j]] : 0.0;
}

void ts_kernel_set_controls(const ts_kernel *k, int v, const double xi[],
                            const double act[], double y[])
{
    const veh *V = &k->veh[v];
    double *c = y + 2 * k->nq;
    for (int l = 0; l < V->d->nloops; l++)
        if (V->xi_off[l] >= 0)
            c[V->xi_off[l]] = xi[l];
    for (int j = 0; j < V->d->ncomponents; j++)
        if (V->act_off[j] >= 0)
            c[V->act_off[j]] = act[j];
}


/* Control surfaces of vehicle V. */
static int nsurfaces(const veh *V)
{
    int n = 0;
    for (int c = 0; c < V->d->ncomponents; c++)
        n += V->in_surf[c] >= 0;
    return n;
}

int ts_kernel_noutput(const ts_kernel *k)
{
    int n = 0;
    for (int v = 0; v < k->nv; v++)
        n += OUT_MEASURES + k->veh[v].d->nloops + nsurfaces(&k->veh[v]);
    return n;
}

const char *ts_kernel_output_name(const ts_kernel *k, int j, char *buf,
                                  size_t size)
{
    static const char *const measure[OUT_MEASURES] = {"depth", "pitch",
                                                      "roll", "yaw"};
    for (int v = 0; v < k->nv && j >= 0; v++) {
        const veh *V = &k->veh[v];
        const char *body = k->sys->bodies[V->body].name;
        if (j < OUT_MEASURES) {
            snprintf(buf, size, "%s.%s", body, measure[j]);
            return buf;
        }
        j -= OUT_MEASURES;
        if (j < V->d->nloops) {
            snprintf(buf, size, "%s.%s.output", body, V->d->loop[j].name);
            return buf;
        }
        j -= V->d->nloops;
        for (int c = 0; c < V->d->ncomponents; c++)
            if (V->in_surf[c] >= 0 && j-- == 0) {
                snprintf(buf, size, "%s.%s.deflection", body,
                         V->d->component[c].name);
                return buf;
            }
    }
    return NULL;
}

int ts_kernel_output_find(const ts_kernel *k, const char *name)
{
    char buf[2 * TS_NAME_MAX + 16];
    int n = ts_kernel_noutput(k);
    for (int j = 0; j < n; j++)
        if (ts_kernel_output_name(k, j, buf, sizeof buf) &&
            !strcmp(buf, name))
            return j;
    return -1;
}

void ts_kernel_outputs(const ts_kernel *k, double out[])
{
    int j = 0;
    for (int v = 0; v < k->nv; v++) {
        const veh *V = &k->veh[v];
        /* depth, pitch, roll, yaw: the ts_measure order is depth, pitch,
         * roll, heading */
        for (int m = 0; m < OUT_MEASURES; m++)
            out[j++] = V->meas[m];
        for (int l = 0; l < V->d->nloops; l++)
            out[j++] = V->out[l];
        for (int c = 0; c < V->d->ncomponents; c++)
            if (V->in_surf[c] >= 0)
                out[j++] = V->delta[c];
    }
}

int ts_kernel_speed_integrator(const ts_kernel *k)
{
    return k->root >= 0 ? k->veh[k->root].spd_off : -1;
}

void ts_kernel_control_state(const ts_kernel *k, int i, ts_control_state *cs)
{
    cs->vehicle = cs->actuator = cs->index = -1;
    for (int v = 0; v < k->nv; v++) {
        const veh *V = &k->veh[v];
        if (V->spd_off == i) {
            cs->vehicle = v;
            cs->actuator = TS_CONTROL_SPEED;
            return;
        }
        for (int l = 0; l < V->d->nloops; l++)
            if (V->xi_off[l] == i) {
                cs->vehicle = v;
                cs->actuator = 0;
                cs->index = l;
                return;
            }
        for (int c = 0; c < V->d->ncomponents; c++)
            if (V->act_off[c] == i) {
                cs->vehicle = v;
                cs->actuator = 1;
                cs->index = c;
                return;
            }
    }
}

void ts_kernel_root_position(const ts_kernel *k, const double y[],
                             double r[3])
{
    const double *p = k->sys->tow.point;
    int ro = ts_kernel_root_offset(k);
    int np = ro < 0 ? 0 : ts_kernel_root_dof(k) == 3 ? 2 : 3;
    for (int j = 0; j < 3; j++)
        r[j] = j < np ? y[ro + j] : p[j];
}

const char *tsi_tow_input_name(int j)
{
    static const char *const names[TS_NINPUT] = {
        "tow.surge",
        "tow.sway",
        "tow.heave",
        "tow.surge_velocity",
        "tow.sway_velocity",
        "tow.heave_velocity",
        "tow.surge_acceleration",
        "tow.sway_acceleration",
        "tow.heave_acceleration",
        "tow.roll",
        "tow.pitch",
        "tow.yaw",
        "tow.roll_velocity",
        "tow.pitch_velocity",
        "tow.yaw_velocity",
        "tow.roll_acceleration",
        "tow.pitch_acceleration",
        "tow.yaw_acceleration"};
    return j >= 0 && j < TS_NINPUT ? names[j] : NULL;
}

static const char *const prop_input[TSI_NPROP] = {
    "thrust", "force.x", "force.y", "force.z", "moment.x", "moment.y",
    "moment.z"};

const char *ts_kernel_input_name(const ts_kernel *k, int j, char *buf,
                                 size_t size)
{
    if (j >= 0 && j < TS_NINPUT) {
        snprintf(buf, size, "%s", tsi_tow_input_name(j));
        return buf;
    }
    for (int v = 0; v < k->nv; v++) {
        const veh *V = &k->veh[v];
        const char *body = k->sys->bodies[V->body].name;
        for (int c = 0; c < V->d->ncomponents; c++)
            if (V->in_surf[c] == j) {
                snprintf(buf, size, "%s.%s", body, V->d->component[c].name);
                return buf;
            }
        for (int l = 0; l < V->d->nloops; l++) {
            if (V->in_loop[l] == j) {
                snprintf(buf, size, "%s.%s", body, V->d->loop[l].name);
                return buf;
            }
            if (V->in_sp[l] == j) {
                snprintf(buf, size, "%s.%s.setpoint", body,
                         V->d->loop[l].name);
                return buf;
            }
        }
        if (V->in_prop >= 0 && j >= V->in_prop && j < V->in_prop + TSI_NPROP) {
            snprintf(buf, size, "%s.%s", body, prop_input[j - V->in_prop]);
            return buf;
        }
        if (V->in_spd >= 0 && j == V->in_spd) {
            snprintf(buf, size, "%s.speed_set", body);
            return buf;
        }
    }
    return NULL;
}

const char *ts_kernel_input_unit(const ts_kernel *k, int j)
{
    if (j >= 0 && j < TS_NINPUT) {
        static const char *const units[6] = {"m", "m/s", "m/s^2",
                                             "rad", "rad/s", "rad/s^2"};
        return units[j / 3];
    }
    for (int v = 0; v < k->nv; v++) {
        const veh *V = &k->veh[v];
        for (int c = 0; c < V->d->ncomponents; c++)
            if (V->in_surf[c] == j &&
                V->d->component[c].type == TS_COMP_BALLAST)
                return "kg";
        for (int l = 0; l < V->d->nloops; l++)
            if (V->in_sp[l] == j)
                return V->d->loop[l].measure == TS_MEASURE_DEPTH ? "m"
                                                                 : "rad";
        if (V->in_prop >= 0 && j >= V->in_prop && j < V->in_prop + TSI_NPROP)
            return j - V->in_prop < 4 ? "N" : "N*m";
        if (V->in_spd >= 0 && j == V->in_spd)
            return "m/s";
    }
    return j < k->nin ? "rad" : NULL; /* a deflection or a loop's output */
}

const char *ts_kernel_output_unit(const ts_kernel *k, int j)
{
    for (int v = 0; v < k->nv && j >= 0; v++) {
        if (j < OUT_MEASURES)
            return j == 0 ? "m" : "rad";
        const veh *V = &k->veh[v];
        j -= OUT_MEASURES + V->d->nloops;
        if (j < 0)
            return "rad";
        /* The deflections, in the order of the control components: a
         * ballast tank's fill in kg. */
        for (int c = 0; c < V->d->ncomponents; c++)
            if (V->in_surf[c] >= 0 && j-- == 0)
                return V->d->component[c].type == TS_COMP_BALLAST ? "kg"
                                                                  : "rad";
    }
    return NULL;
}

/* What a vehicle's input j is: a surface's deflection, a loop's set
 * point, or another (a loop's input, a towing vehicle's). */
enum { INPUT_OTHER, INPUT_SURFACE, INPUT_SETPOINT };
static int input_kind(const ts_kernel *k, int j)
{
    for (int v = 0; v < k->nv && j >= TS_NINPUT; v++) {
        const veh *V = &k->veh[v];
        for (int c = 0; c < V->d->ncomponents; c++)
            if (V->in_surf[c] == j)
                return INPUT_SURFACE;
        for (int l = 0; l < V->d->nloops; l++)
            if (V->in_sp[l] == j)
                return INPUT_SETPOINT;
    }
    return INPUT_OTHER;
}

int ts_kernel_input_is_surface(const ts_kernel *k, int j)
{
    return input_kind(k, j) == INPUT_SURFACE;
}

int ts_kernel_input_is_setpoint(const ts_kernel *k, int j)
{
    return input_kind(k, j) == INPUT_SETPOINT;
}

int ts_kernel_input_find(const ts_kernel *k, const char *name)
{
    char buf[2 * TS_NAME_MAX + 8];
    for (int j = 0; j < k->nin; j++)
        if (ts_kernel_input_name(k, j, buf, sizeof buf) &&
            !strcmp(buf, name))
            return j;
    return -1;
}
int ts_kernel_vehicle_body(const ts_kernel *k, int v) { return k->veh[v].body; }
int ts_kernel_root(const ts_kernel *k) { return k->root; }
int ts_kernel_root_offset(const ts_kernel *k)
{
    if (k->root < 0)
        return -1;
    const veh *V = &k->veh[k->root];
    return V->qoff + (V->dof == 3 ? 1 : 3);
}
int ts_kernel_root_dof(const ts_kernel *k)
{
    return k->root >= 0 ? k->veh[k->root].dof : 0;
}
void ts_kernel_set_thrust_bias(ts_kernel *k, double thrust)
{
    if (k->root >= 0)
        k->veh[k->root].thrust_bias = thrust;
}
double ts_kernel_thrust_bias(const ts_kernel *k)
{
    return k->root >= 0 ? k->veh[k->root].thrust_bias : 0.0;
}
void ts_kernel_set_turn_deflection(ts_kernel *k, double delta)
{
    if (k->root >= 0)
        k->veh[k->root].turn_delta = delta;
}
double ts_kernel_turn_deflection(const ts_kernel *k)
{
    return k->root >= 0 ? k->veh[k->root].turn_delta : 0.0;
}
double ts_kernel_thrust(const ts_kernel *k)
{
    return k->root >= 0 ? k->veh[k->root].thrust : 0.0;
}
int ts_kernel_vehicle_offset(const ts_kernel *k, int v)
{
    return k->veh[v].qoff;
}

void ts_kernel_set_frame(ts_kernel *k, const ts_frame *f) { k->frame = *f; }

void ts_kernel_get_frame(const ts_kernel *k, ts_frame *f) { *f = k->frame; }

void ts_kernel_set_bending_scale(ts_kernel *k, double scale)
{
    k->bend_scale = scale;
}

/* Direction and chart axes of a link from its angles. */
static inline void link_axes(const ts_kernel *k, int l, double t1, double t2,
                             double n[3], double e1[3], double e2[3],
                             double *c2out, double *s2out)
{
    double c1 = cos(t1), s1 = sin(t1), c2 = cos(t2), s2 = sin(t2);
    double nh[3] = {-c1 * c2, -s2, s1 * c2};
    double e1h[3] = {s1, 0.0, c1};
    double e2h[3] = {c1 * s2, -c2, -s1 * s2};
    if (k->charted[l]) {
        const double *R = k->chart + 9 * l;
        mat3_mul(R, nh, n);
        mat3_mul(R, e1h, e1);
        mat3_mul(R, e2h, e2);
    } else {
        v3_copy(nh, n);
        v3_copy(e1h, e1);
        v3_copy(e2h, e2);
    }
    *c2out = c2;
    *s2out = s2;
}

void ts_kernel_direction(const ts_kernel *k, int link, double t1, double t2,
                         double n[3])
{
    double e1[3], e2[3], c2, s2;
    link_axes(k, link, t1, t2, n, e1, e2, &c2, &s2);
}

void tsi_vehicle_flow(const ts_frame *f, const ts_vehicle *d,
                      tsi_vehicle_state *st)
{
    double w[3], rB[3], rdB[3];
    tsi_rel_velocity(f, st->rO, st->rdO, w);
    mat3_tmul(st->R, w, st->wO_b);
    tsi_vehicle_point(d, st, d->buoyancy_centre, rB, rdB);
    st->frac = d->surface_diameter > 0
                   ? tsi_cylinder_submerged(rB[2], d->surface_diameter)
                   : (rB[2] > 0 ? 1.0 : 0.0);
}

/* Fill dydt[n] with NaN and return code: the kernel never returns numbers
 * computed outside the model. */
static int refuse(const ts_kernel *k, double dydt[], int code)
{
    int n = 2 * k->nq + k->nc;
    for (int i = 0; i < n; i++)
        dydt[i] = NAN;
    return code;
}

/* Body axes: rho_P = P - A of the point link l starts from. */
static void link_lever(const veh *V, const ts_link *L, double rho[3])
{
    for (int j = 0; j < 3; j++)
        rho[j] = L->up_point[j] - V->d->attach[j];
}

/* A vehicle's three 1-2-3 angles and their rates in state y: a surface
 * ship's roll and pitch are 0, its yaw the one angle coordinate. */
static void vehicle_angles(const ts_kernel *k, const veh *V, const double y[],
                           double th[3], double thd[3])
{
    const double *a = y + V->qoff, *ad = y + k->nq + V->qoff;
    if (V->dof == 3) {
        th[0] = th[1] = thd[0] = thd[1] = 0.0;
        th[2] = a[0];
        thd[2] = ad[0];
        return;
    }
    for (int j = 0; j < 3; j++) {
        th[j] = a[j];
        thd[j] = ad[j];
    }
}

/* A vehicle's kinematics once its node's position and velocity are known,
 * and the points its child cables start from. Returns 1 when its chart is
 * singular. */
static int vehicle_kinematics(ts_kernel *k, veh *V, const double y[])
{
    double th[3], thd[3];
    vehicle_angles(k, V, y, th, thd);
    tsi_vehicle_kinematics(V->d, V->chart, th, thd, k->frame.turn_rate,
                           k->r + 3 * V->node, k->rd + 3 * V->node, &V->st);
    tsi_vehicle_flow(&k->frame, V->d, &V->st);
    const ts_node *nd = &k->sys->nodes[V->node];
    for (int c = nd->child_begin; c < nd->child_end; c++) {
        int l = k->sys->child_links[c];
        tsi_vehicle_point(V->d, &V->st, k->sys->links[l].up_point,
                          k->ur + 3 * l, k->urd + 3 * l);
    }
    return !(fabs(V->st.c2) >= TS_CHART_MIN);
}

/* sym3 S (M axes) to body axes: R^T S R, as a full 3x3. */
static void sym3_to_body(const double R[9], const double S[6], double B[9])
{
    double F[9] = {S[0], S[3], S[4], S[3], S[1], S[5], S[4], S[5], S[2]};
    double T[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            T[3 * i + j] = F[3 * i] * R[j] + F[3 * i + 1] * R[3 + j] +
                           F[3 * i + 2] * R[6 + j];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            B[3 * i + j] = R[i] * T[j] + R[3 + i] * T[3 + j] +
                           R[6 + i] * T[6 + j];
}

/* A mass M3 (3x3, body axes) at lever rho (body axes, from A) whose point
 * accelerates as J (a_A, alpha) + b, J = [I, -S(rho)], under the force f
 * (body axes): M6 += J^T M3 J, G += J^T (f - M3 b). */
static void add_point(double M6[36], double G[6], const double M3[9],
                      const double rho[3], const double f[3],
                      const double b[3])
{
    double MS[9], S[9] = {0, -rho[2], rho[1], rho[2], 0, -rho[0],
                          -rho[1], rho[0], 0};
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            MS[3 * i + j] = M3[3 * i] * S[j] + M3[3 * i + 1] * S[3 + j] +
                            M3[3 * i + 2] * S[6 + j];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++) {
            double SMS = S[3 * i] * MS[j] + S[3 * i + 1] * MS[3 + j] +
                         S[3 * i + 2] * MS[6 + j];
            M6[6 * i + j] += M3[3 * i + j];
            M6[6 * i + 3 + j] -= MS[3 * i + j];
            M6[6 * (3 + i) + j] -= MS[3 * j + i];
            M6[6 * (3 + i) + 3 + j] -= SMS;
        }
    double h[3], x[3];
    for (int i = 0; i < 3; i++)
        h[i] = f[i] - (M3[3 * i] * b[0] + M3[3 * i + 1] * b[1] +
                       M3[3 * i + 2] * b[2]);
    v3_cross(rho, h, x);
    for (int i = 0; i < 3; i++) {
        G[i] += h[i];
        G[3 + i] += x[i];
    }
}

/* om x (om x rho). */
static void centripetal(const double om[3], const double rho[3], double b[3])
{
    double t[3];
    v3_cross(om, rho, t);
    v3_cross(om, t, b);
}

/* The part of the acceleration (body axes) of the point at lever rho from
 * A that the body's (a_A, alpha) do not give: om x (om x rho), and a
 * towing vehicle's prescribed motion of its cables' starting points. */
static void point_bias(const veh *V, const double rho[3], double b[3])
{
    centripetal(V->st.om_b, rho, b);
    if (!V->root)
        return; /* a towed vehicle: no prescribed motion */
    double p[3], x[3];
    for (int j = 0; j < 3; j++)
        p[j] = rho[j] + V->d->attach[j];
    v3_cross(V->shift_al, p, x);
    for (int j = 0; j < 3; j++)
        b[j] += V->shift_a[j] + x[j];
}

/* A vehicle's controller, inertia and its own loads (V->M6, V->G). */
static void vehicle_own_loads(ts_kernel *k, veh *V, const double y[],
                              const double u[], double rho, double g)
{
    const ts_vehicle *d = V->d;
    const double *c = y + 2 * k->nq;
    double xi[TS_VEHICLE_MAX_LOOPS], ul[TS_VEHICLE_MAX_LOOPS];
    double sp[TS_VEHICLE_MAX_LOOPS];
    double act[TS_VEHICLE_MAX_COMPONENTS], us[TS_VEHICLE_MAX_COMPONENTS];
    for (int l = 0; l < d->nloops; l++) {
        xi[l] = V->xi_off[l] >= 0 ? c[V->xi_off[l]] : 0.0;
        ul[l] = u[V->in_loop[l]];
        sp[l] = V->sp[l] + u[V->in_sp[l]];
    }
    for (int j = 0; j < d->ncomponents; j++) {
        act[j] = V->act_off[j] >= 0 ? c[V->act_off[j]] : 0.0;
        us[j] = V->in_surf[j] >= 0 ? u[V->in_surf[j]] : 0.0;
        if (V->root && j == k->sys->tow.turn_surface)
            us[j] += V->turn_delta;
    }
    tsi_vehicle_measure(&V->st, V->meas, V->rate);
    tsi_control_in in = {V->meas, V->rate, xi,   act,      us,
                         ul,      sp,      V->mode, V->frozen, k->steady};
    tsi_vehicle_control(d, &in, V->out, V->delta, V->xi_dot, V->act_dot);
    tsi_vehicle_mass6(d, V->mass, &V->st, V->M6);
    tsi_vehicle_loads(d, V->ws, V->mass, rho, g, &V->st, V->delta, V->G,
                      NULL);
    if (V->root) {
        /* Thrust along body x at its point, and the external force and
         * moment inputs (body axes), as a generalised force about A. */
        const double *up = u + V->in_prop;
        const double *pp = d->propulsion.position;
        /* The power law sees the surge through the water, the speed
         * controller the tow point's speed through the water. */
        double wA[3];
        tsi_rel_velocity(&k->frame, V->st.rA, V->st.rdA, wA);
        double u_law = d->propulsion.type == TS_PROP_SPEED ? v3_norm(wA)
                                                           : V->st.wO_b[0];
        /* A PI speed controller: its integral term joins the bias; the
         * integrator holds while the law is capped and the vehicle slower
         * than its set speed (anti-windup). */
        /* The set-speed input moves the speed controller's set speed. */
        ts_propulsion law = d->propulsion;
        const ts_propulsion *pr = &law;
        if (V->in_spd >= 0)
            law.speed += u[V->in_spd];
        double bias = V->thrust_bias;
        if (V->spd_off >= 0) {
            double e = pr->speed - u_law;
            bias += pr->ki * c[V->spd_off];
            V->spd_dot = e > 0 && bias + pr->gain * e >= pr->max_thrust
                             ? 0.0
                             : e;
        }
        V->thrust = ts_propulsion_thrust(pr, u_law, bias, up[0]);
        double f[3] = {V->thrust, 0, 0}, lever[3], m[3];
        for (int j = 0; j < 3; j++)
            lever[j] = pp[j] - d->attach[j];
        v3_cross(lever, f, m);
        for (int j = 0; j < 3; j++) {
            V->G[j] += f[j] + up[1 + j];
            V->G[3 + j] += m[j] + up[4 + j];
        }
    }
}

/* A vehicle's controller, inertia and loads, with the masses and loads
 * its child cables put at their starting points. */
static void vehicle_loads(ts_kernel *k, veh *V, const double y[],
                          const double u[], double rho, double g)
{
    vehicle_own_loads(k, V, y, u, rho, g);
    const ts_node *nd = &k->sys->nodes[V->node];
    for (int j = nd->child_begin; j < nd->child_end; j++) {
        int l = k->sys->child_links[j];
        double lever[3], M3[9], f[3], b[3];
        link_lever(V, &k->sys->links[l], lever);
        sym3_to_body(V->st.R, k->uM + 6 * l, M3);
        mat3_tmul(V->st.R, k->uQ + 3 * l, f);
        point_bias(V, lever, b);
        add_point(V->M6, V->G, M3, lever, f, b);
    }
    memcpy(V->M6h, V->M6, sizeof V->M6);
}

/* Eliminate the body: W = J M6h^-1 J^T and a_free = J M6h^-1 G, both to
 * M. Returns -1 when M6h is not positive definite. */
static int vehicle_articulate(veh *V)
{
    if (tsi_chol6(V->M6h, V->L6) != 0)
        return -1;
    double W[6], e[6], Lw[6], Wi[9];
    for (int j = 0; j < 3; j++) {
        memset(e, 0, sizeof e);
        e[j] = 1.0;
        tsi_chol6_solve(V->L6, e);
        W[j] = e[j];
        if (j == 0) {
            W[3] = e[1];
            W[4] = e[2];
        } else if (j == 1) {
            W[5] = e[2];
        }
    }
    if (sym3_chol(W, Lw) != 0)
        return -1;
    for (int j = 0; j < 3; j++) {
        double x[3] = {j == 0, j == 1, j == 2};
        sym3_chol_solve(Lw, x);
        for (int i = 0; i < 3; i++)
            Wi[3 * i + j] = x[i];
    }
    /* R W^-1 R^T, symmetric: keep the sym3 entries. */
    const double *R = V->st.R;
    double T[9], F[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            T[3 * i + j] = R[3 * i] * Wi[j] + R[3 * i + 1] * Wi[3 + j] +
                           R[3 * i + 2] * Wi[6 + j];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            F[3 * i + j] = T[3 * i] * R[3 * j] + T[3 * i + 1] * R[3 * j + 1] +
                           T[3 * i + 2] * R[3 * j + 2];
    V->Winv[0] = F[0];
    V->Winv[1] = F[4];
    V->Winv[2] = F[8];
    V->Winv[3] = 0.5 * (F[1] + F[3]);
    V->Winv[4] = 0.5 * (F[2] + F[6]);
    V->Winv[5] = 0.5 * (F[5] + F[7]);
    memcpy(e, V->G, sizeof e);
    tsi_chol6_solve(V->L6, e);
    mat3_mul(R, e, V->afree);
    return 0;
}

/* The body's accelerations once its attach point's acceleration a_A (M)
 * is known: F_j = W^-1 (a_A - a_free), (a_A, alpha) = M6h^-1 (G + (F_j,
 * 0)). */
static void vehicle_accelerate(veh *V, const double aA[3])
{
    double d[3] = {aA[0] - V->afree[0], aA[1] - V->afree[1],
                   aA[2] - V->afree[2]};
    double Fb[3];
    sym3_mul(V->Winv, d, V->Fj);
    mat3_tmul(V->st.R, V->Fj, Fb);
    for (int j = 0; j < 6; j++)
        V->a6[j] = V->G[j] + (j < 3 ? Fb[j] : 0.0);
    tsi_chol6_solve(V->L6, V->a6);
    mat3_mul(V->st.R, V->a6 + 3, V->alpha_m);
}

/* A surface ship's accelerations (doc/model.md section 8): heave, roll
 * and pitch are held, a_A,z = alpha_x = alpha_y = 0 in body axes (whose z
 * is M's with roll and pitch 0), so M6h (a_A, alpha) = Gh + (0, 0, h_z,
 * h_x, h_y, 0) leaves the 3x3 system of surge, sway and yaw; the hull's
 * reactions h follow, V->held. Returns -1 when that 3x3 is not positive
 * definite. */
static int root_surface_solve(veh *V)
{
    static const int fr[3] = {0, 1, 5}, hc[3] = {2, 3, 4};
    const double *M = V->M6h;
    double S[6] = {M[0], M[7], M[35], M[1], M[5], M[11]}, L[6], x[3];
    if (sym3_chol(S, L) != 0)
        return -1;
    for (int i = 0; i < 3; i++)
        x[i] = V->G[fr[i]];
    sym3_chol_solve(L, x);
    memset(V->a6, 0, sizeof V->a6);
    for (int i = 0; i < 3; i++) {
        V->a6[fr[i]] = x[i];
        V->held[i] = -V->G[hc[i]];
        for (int j = 0; j < 3; j++)
            V->held[i] += M[6 * hc[i] + fr[j]] * x[j];
    }
    return 0;
}

/* Inertial acceleration (M) of the point link l starts from on V. */
static void vehicle_point_accel(const veh *V, const ts_link *L, double a[3])
{
    double lever[3], x[3], b[3], ab[3];
    link_lever(V, L, lever);
    v3_cross(V->a6 + 3, lever, x);
    point_bias(V, lever, b);
    for (int j = 0; j < 3; j++)
        ab[j] = V->a6[j] + x[j] + b[j];
    mat3_mul(V->st.R, ab, a);
}

/* 2. The link-local assembly shared by f(y, u) and the node residual:
 * from node positions k->r and velocities k->rd (relative to M), link
 * directions k->n and strains k->strain, the external load Q, the 3x3
 * mass matrix M and the frame part afr of the acceleration of every node,
 * and each link's submerged fraction. Each link adds to its two end nodes
 * (and a bending joint to three), each body to its node: O(nlinks). A
 * vehicle's own loads follow (vehicle_loads, in ts_kernel_eval). */
static void assemble(ts_kernel *k)
{
    const ts_system *sys = k->sys;
    const ts_link *links = sys->links;
    const ts_node *nodes = sys->nodes;
    const int nl = k->nl, nn = k->nn;
    const double rho = sys->env.water_density, g = sys->env.gravity;
    const int added = sys->has_added_mass;
    for (int i = 0; i < nn; i++) {
        double *Q = k->Q + 3 * i, *M = k->M + 6 * i;
        v3_set(Q, 0, 0, 0);
        M[0] = M[1] = M[2] = nodes[i].mass;
        M[3] = M[4] = M[5] = 0.0;
        tsi_frame_accel(&k->frame, k->r + 3 * i, k->rd + 3 * i,
                        k->afr + 3 * i);
        int b = nodes[i].body;
        if (b >= 0 && sys->bodies[b].type != TS_BODY_VEHICLE) {
            /* A cylinder's axis lies along the link that ends at it. */
            const double *axis = k->n + 3 * nodes[i].link;
            double w[3], F[3], frac;
            tsi_rel_velocity(&k->frame, k->r + 3 * i, k->rd + 3 * i, w);
            tsi_body_load(&sys->bodies[b], rho, g, k->r[3 * i + 2], w, axis,
                          F, &frac);
            v3_axpy(1.0, F, Q);
            if (added)
                tsi_body_added_mass(&sys->bodies[b], rho, frac, axis, M);
        }
    }
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        const double *n = k->n + 3 * l;
        const double *rp = k->r + 3 * L->upper, *rdp = k->rd + 3 * L->upper;
        double *Qp = k->Q + 3 * L->upper, *Mp = k->M + 6 * L->upper;
        if (L->up_body >= 0) {
            /* The upper end is a point of a vehicle: what lands there is
             * the vehicle's (vehicle_loads). */
            rp = k->ur + 3 * l;
            rdp = k->urd + 3 * l;
            Qp = k->uQ + 3 * l;
            Mp = k->uM + 6 * l;
            v3_set(Qp, 0, 0, 0);
            Mp[0] = Mp[1] = Mp[2] = 0.5 * L->mass;
            Mp[3] = Mp[4] = Mp[5] = 0.0;
            tsi_frame_accel(&k->frame, rp, rdp, k->uafr + 3 * l);
        }
        const double *rk = k->r + 3 * L->lower;
        double rm[3], vm[3], w[3], F[3];
        for (int j = 0; j < 3; j++) {
            rm[j] = 0.5 * (rp[j] + rk[j]);
            vm[j] = 0.5 * (rdp[j] + k->rd[3 * L->lower + j]);
        }
        tsi_rel_velocity(&k->frame, rm, vm, w);
        tsi_link_load(L, rho, g, n, rp[2], rk[2], w, F, &k->sub[l]);
        v3_axpy(0.5, F, Qp);
        v3_axpy(0.5, F, k->Q + 3 * L->lower);
        if (added && L->can > 0 && k->sub[l] > 0) {
            double A = L->can * rho * M_PI * 0.25 * L->diameter *
                       L->diameter * L->length * k->sub[l];
            sym3_add_normal(Mp, 0.5 * A, n);
            sym3_add_normal(k->M + 6 * L->lower, 0.5 * A, n);
        }
        if (L->ei > 0) {
            /* U = 1/2 (EI / lbar) alpha^2 with lbar from the unstretched
             * lengths (a spring constant of the cable), so -dU/dr divides
             * by the current lengths l (1 + e): tsi_bending takes the
             * current lengths and EI scaled by their mean over lbar. */
            const ts_link *B = &links[L->next];
            double la = L->length * (1.0 + k->strain[l]);
            double lb = B->length * (1.0 + k->strain[L->next]);
            double ei = L->ei * k->bend_scale * (la + lb) /
                        (L->length + B->length);
            double Fi[3], Fj[3], Fk[3];
            tsi_bending(ei, la, lb, n, k->n + 3 * L->next, Fi, Fj, Fk);
            v3_axpy(1.0, Fi, Qp);
            v3_axpy(1.0, Fj, k->Q + 3 * L->lower);
            v3_axpy(1.0, Fk, k->Q + 3 * B->lower);
        }
    }
}

/* The controller states' rates of V's last evaluation into cdot (its
 * integrators' and actuators' places, a PI speed controller's
 * integrator's). */
static void control_rates(const veh *V, double cdot[])
{
    for (int l = 0; l < V->d->nloops; l++)
        if (V->xi_off[l] >= 0)
            cdot[V->xi_off[l]] = V->xi_dot[l];
    for (int j = 0; j < V->d->ncomponents; j++)
        if (V->act_off[j] >= 0)
            cdot[V->act_off[j]] = V->act_dot[j];
    if (V->spd_off >= 0)
        cdot[V->spd_off] = V->spd_dot;
}

/* The tow inputs (doc/towing-vehicle.md section 8): a translation x and
 * a small rotation theta (u[TS_TOW_ROT..]) of the ship, with their rates
 * and accelerations, move a cable's start point r by x + theta x r (M
 * axes), its velocity by x' + theta' x r, its acceleration by x'' +
 * theta'' x r: linear in the inputs. A prescribed tow point is the one
 * start point, r = tow.point from M's origin: k->r, k->rd of node 0 and
 * k->tow_acc. With a towing vehicle the points its cables start from move
 * relative to the body, r = R p from its origin O (p body axes, the
 * cable's `at`), on top of the body's own motion (vehicle_kinematics has
 * placed them): k->ur, k->urd, and the accelerations (body axes)
 * shift_a + shift_al x p that point_bias adds. */
static void root_tow_inputs(ts_kernel *k, veh *Root, const double u[])
{
    const ts_system *sys = k->sys;
    const double *x = u, *xd = u + 3, *xdd = u + 6;
    const double *th = u + TS_TOW_ROT, *thd = th + 3, *thdd = th + 6;
    double dr[3], dv[3], da[3];
    if (!Root) {
        const double *r = sys->tow.point;
        v3_cross(th, r, dr);
        v3_cross(thd, r, dv);
        v3_cross(thdd, r, da);
        for (int j = 0; j < 3; j++) {
            k->r[j] = r[j] + x[j] + dr[j];
            k->rd[j] = xd[j] + dv[j];
            k->tow_acc[j] = xdd[j] + da[j];
        }
        return;
    }
    const ts_node *n0 = &sys->nodes[0];
    for (int c = n0->child_begin; c < n0->child_end; c++) {
        int l = sys->child_links[c];
        double r[3];
        mat3_mul(Root->st.R, sys->links[l].up_point, r);
        v3_cross(th, r, dr);
        v3_cross(thd, r, dv);
        for (int j = 0; j < 3; j++) {
            k->ur[3 * l + j] += x[j] + dr[j];
            k->urd[3 * l + j] += xd[j] + dv[j];
        }
    }
    mat3_tmul(Root->st.R, xdd, Root->shift_a);
    mat3_tmul(Root->st.R, thdd, Root->shift_al);
}

int ts_kernel_eval(ts_kernel *k, const double y[], const double u[],
                   double dydt[])
{
    const ts_system *sys = k->sys;
    const ts_link *links = sys->links;
    const int nl = k->nl, nn = k->nn, nq = k->nq;
    const double *qd = y + nq;
    const double rho = sys->env.water_density, g = sys->env.gravity;
    if (!u)
        u = k->uzero;

    /* 1. Kinematics. The tow point is prescribed, or the towing
     * vehicle's attach point, whose position in M is a coordinate. */
    int chart_bad = 0, slack_bad = 0;
    veh *Root = k->root >= 0 ? &k->veh[k->root] : NULL;
    if (Root) {
        int ro = ts_kernel_root_offset(k), np = Root->dof == 3 ? 2 : 3;
        for (int j = 0; j < 3; j++) {
            k->r[j] = j < np ? y[ro + j] : sys->tow.point[j];
            k->rd[j] = j < np ? qd[ro + j] : 0.0;
        }
        if (vehicle_kinematics(k, Root, y))
            chart_bad = 1;
    }
    root_tow_inputs(k, Root, u);
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        const int o = k->off[l];
        double *n = k->n + 3 * l, *nd = k->nd + 3 * l;
        const double *rp = k->r + 3 * L->upper, *rdp = k->rd + 3 * L->upper;
        if (L->up_body >= 0) {
            rp = k->ur + 3 * l;
            rdp = k->urd + 3 * l;
        }
        double *rk = k->r + 3 * L->lower, *rdk = k->rd + 3 * L->lower;
        double *e1 = k->e1 + 3 * l, *e2 = k->e2 + 3 * l;
        double c2, s2;
        link_axes(k, l, y[o], y[o + 1], n, e1, e2, &c2, &s2);
        k->c2[l] = c2;
        k->s2[l] = s2;
        if (!(fabs(c2) >= TS_CHART_MIN))
            chart_bad = 1;
        double a1 = c2 * qd[o], a2 = qd[o + 1];
        for (int j = 0; j < 3; j++)
            nd[j] = a1 * e1[j] + a2 * e2[j];
        /* An elastic link's third coordinate is its strain e: length
         * l (1 + e), tension EA e + Cv l e', never compressive. */
        double len = L->length, lrate = 0.0;
        if (L->elastic) {
            double e = y[o + 2], ed = qd[o + 2];
            k->strain[l] = e;
            len = L->length * (1.0 + e);
            lrate = L->length * ed;
            if (!(len > 0))
                slack_bad = 1;
            double T = L->ea * e + L->damping * lrate;
            k->t[l] = T > 0 ? T : 0.0;
        }
        for (int j = 0; j < 3; j++) {
            rk[j] = rp[j] + len * n[j];
            rdk[j] = rdp[j] + len * nd[j] + lrate * n[j];
        }
        int v = k->node_veh[L->lower];
        if (v >= 0 && vehicle_kinematics(k, &k->veh[v], y))
            chart_bad = 1;
    }
    if (slack_bad)
        return refuse(k, dydt, TS_ESINGULAR);
    if (chart_bad)
        return refuse(k, dydt, TS_CHART);

    /* 2. Loads, mass matrices and frame accelerations. */
    assemble(k);
    for (int v = 0; v < k->nv; v++)
        vehicle_loads(k, &k->veh[v], y, u, rho, g);

    /* 3a. Free ends to tow point: articulated mass and load. An elastic
     * link passes no inertia up: its known tension pulls both ends. */
    for (int i = 1; i < nn; i++) {
        memcpy(k->Mh + 6 * i, k->M + 6 * i, 6 * sizeof(double));
        v3_copy(k->Q + 3 * i, k->Fh + 3 * i);
    }
    if (sys->has_elastic)
        for (int l = 0; l < nl; l++)
            if (links[l].elastic) {
                const ts_link *L = &links[l];
                if (L->up_body >= 0) {
                    veh *V = &k->veh[k->node_veh[L->upper]];
                    double lever[3], f[3], T[3], zero3[3] = {0, 0, 0};
                    static const double none[9] = {0};
                    for (int j = 0; j < 3; j++)
                        T[j] = k->t[l] * k->n[3 * l + j];
                    link_lever(V, L, lever);
                    mat3_tmul(V->st.R, T, f);
                    add_point(V->M6h, V->G, none, lever, f, zero3);
                } else if (L->upper > 0) {
                    v3_axpy(k->t[l], k->n + 3 * l, k->Fh + 3 * L->upper);
                }
                v3_axpy(-k->t[l], k->n + 3 * l, k->Fh + 3 * L->lower);
            }
    for (int l = nl - 1; l >= 0; l--) {
        const ts_link *L = &links[l];
        int i = L->lower, p = L->upper;
        const double *n = k->n + 3 * l, *nd = k->nd + 3 * l;
        double *Mh = k->Mh + 6 * i, *gi = k->g + 3 * i, *wi = k->w + 3 * i;
        double Lc[6];
        int v = k->node_veh[i];
        if (v >= 0) {
            /* The body and its child cables are done: they hang on node
             * i as W^-1. */
            veh *V = &k->veh[v];
            if (vehicle_articulate(V) != 0)
                return refuse(k, dydt, TS_ESINGULAR);
            for (int j = 0; j < 6; j++)
                Mh[j] += V->Winv[j];
            double f[3];
            sym3_mul(V->Winv, V->afree, f);
            v3_axpy(1.0, f, k->Fh + 3 * i);
        }
        if (sym3_chol(Mh, Lc) != 0)
            return refuse(k, dydt, TS_ESINGULAR);
        v3_copy(k->Fh + 3 * i, gi);
        sym3_chol_solve(Lc, gi);
        if (L->elastic)
            continue;
        v3_copy(n, wi);
        sym3_chol_solve(Lc, wi);
        double D = v3_dot(n, wi);
        const double *afr_p = L->up_body >= 0 ? k->uafr + 3 * l
                                              : k->afr + 3 * p;
        double da[3] = {k->afr[3 * i] - afr_p[0],
                        k->afr[3 * i + 1] - afr_p[1],
                        k->afr[3 * i + 2] - afr_p[2]};
        double rhs = v3_dot(n, da) - L->length * v3_dot(nd, nd);
        double beta = (v3_dot(n, gi) - rhs) / D;
        k->D[l] = D;
        k->beta[l] = beta;
        if (L->up_body >= 0) {
            /* t = beta - n.a_P / D with a_P = J (a_A, alpha) + b: a
             * rank-one update of the body's inertia. */
            veh *V = &k->veh[k->node_veh[p]];
            double lever[3], nb[3], M3[9], f[3], b[3];
            link_lever(V, L, lever);
            mat3_tmul(V->st.R, n, nb);
            for (int a = 0; a < 3; a++) {
                f[a] = beta * nb[a];
                for (int c = 0; c < 3; c++)
                    M3[3 * a + c] = nb[a] * nb[c] / D;
            }
            point_bias(V, lever, b);
            add_point(V->M6h, V->G, M3, lever, f, b);
        } else if (p > 0) {
            sym3_add_outer(k->Mh + 6 * p, 1.0 / D, n);
            v3_axpy(beta, n, k->Fh + 3 * p);
        }
    }

    /* 3b. Tow point to free ends: tensions and accelerations. The towing
     * vehicle has absorbed the whole tree: M6h (a_A, alpha) = G. */
    if (Root && Root->dof == 3) {
        if (root_surface_solve(Root) != 0)
            return refuse(k, dydt, TS_ESINGULAR);
        mat3_mul(Root->st.R, Root->a6 + 3, Root->alpha_m);
        mat3_mul(Root->st.R, Root->a6, k->a);
        v3_set(Root->Fj, 0, 0, 0);
    } else if (Root) {
        if (tsi_chol6(Root->M6h, Root->L6) != 0)
            return refuse(k, dydt, TS_ESINGULAR);
        memcpy(Root->a6, Root->G, sizeof Root->a6);
        tsi_chol6_solve(Root->L6, Root->a6);
        mat3_mul(Root->st.R, Root->a6 + 3, Root->alpha_m);
        mat3_mul(Root->st.R, Root->a6, k->a);
        v3_set(Root->Fj, 0, 0, 0);
    } else {
        for (int j = 0; j < 3; j++)
            k->a[j] = k->afr[j] + k->tow_acc[j];
    }
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        int i = L->lower, p = L->upper;
        const double *n = k->n + 3 * l, *ap = k->a + 3 * p;
        if (L->up_body >= 0) {
            vehicle_point_accel(&k->veh[k->node_veh[p]], L, k->ua + 3 * l);
            ap = k->ua + 3 * l;
        }
        if (L->elastic) {
            v3_copy(k->g + 3 * i, k->a + 3 * i);
        } else {
            double t = k->beta[l] - v3_dot(n, ap) / k->D[l];
            k->t[l] = t;
            double *ai = k->a + 3 * i;
            for (int j = 0; j < 3; j++)
                ai[j] = k->g[3 * i + j] - t * k->w[3 * i + j];
        }
        if (k->node_veh[i] >= 0)
            vehicle_accelerate(&k->veh[k->node_veh[i]], k->a + 3 * i);
    }

    /* 4. Relative accelerations and angle accelerations. */
    for (int j = 0; j < 3; j++)
        k->rdd[j] = Root ? k->a[j] - k->afr[j] : k->tow_acc[j];
    for (int i = 1; i < nn; i++)
        for (int j = 0; j < 3; j++)
            k->rdd[3 * i + j] = k->a[3 * i + j] - k->afr[3 * i + j];
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        const double *ri = k->rdd + 3 * L->lower, *rp = k->rdd + 3 * L->upper;
        double rP[3];
        if (L->up_body >= 0) {
            for (int j = 0; j < 3; j++)
                rP[j] = k->ua[3 * l + j] - k->uafr[3 * l + j];
            rp = rP;
        }
        const int o = k->off[l];
        const double *e1 = k->e1 + 3 * l, *e2 = k->e2 + 3 * l;
        double dd2[3] = {ri[0] - rp[0], ri[1] - rp[1], ri[2] - rp[2]};
        double t1d = qd[o], t2d = qd[o + 1];
        double c2 = k->c2[l], s2 = k->s2[l];
        /* d'' = len n'' + 2 len' n' + len'' n with n.n' = 0 and
         * n.n'' = -|n'|^2: the e1, e2 parts of n'' and the strain's. */
        double len = L->length, a1 = v3_dot(e1, dd2), a2 = v3_dot(e2, dd2);
        if (L->elastic) {
            double e = y[o + 2], ed = qd[o + 2];
            len = L->length * (1.0 + e);
            double lrate2 = 2.0 * L->length * ed;
            a1 -= lrate2 * c2 * t1d;
            a2 -= lrate2 * t2d;
            const double *nd = k->nd + 3 * l;
            dydt[o + 2] = ed;
            dydt[nq + o + 2] = v3_dot(k->n + 3 * l, dd2) / L->length +
                               (1.0 + e) * v3_dot(nd, nd);
        }
        a1 /= len;
        a2 /= len;
        dydt[o] = t1d;
        dydt[o + 1] = t2d;
        dydt[nq + o] = (a1 + 2.0 * s2 * t1d * t2d) / c2;
        dydt[nq + o + 1] = a2 - c2 * s2 * t1d * t1d;
    }
    double *cdot = dydt + 2 * nq;
    for (int v = 0; v < k->nv; v++) {
        veh *V = &k->veh[v];
        double th[3], thd[3], thdd[3];
        vehicle_angles(k, V, y, th, thd);
        tsi_vehicle_angle_accel(&V->st, th, thd, k->frame.turn_rate,
                                k->frame.turn_accel, V->alpha_m, thdd);
        /* A surface ship: its yaw, then x and y of its tow point. */
        int na = V->dof == 3 ? 1 : 3, np = V->dof == 3 ? 2 : 3;
        for (int j = 0; j < na; j++) {
            dydt[V->qoff + j] = thd[3 - na + j];
            dydt[nq + V->qoff + j] = thdd[3 - na + j];
        }
        if (V->root)
            for (int j = 0; j < np; j++) {
                dydt[V->qoff + na + j] = qd[V->qoff + na + j];
                dydt[nq + V->qoff + na + j] = k->rdd[j];
            }
        control_rates(V, cdot);
    }
    return TS_OK;
}

int ts_kernel_rhs(double t, const double y[], const double u[], double dydt[],
                  void *params)
{
    (void)t;
    return ts_kernel_eval((ts_kernel *)params, y, u, dydt);
}

int tsi_kernel_residual(ts_kernel *k, const double r[], const double v[],
                        const double a[], const double t[], const double yv[],
                        const double thdd[], const double u[], double R[])
{
    const ts_system *sys = k->sys;
    const ts_link *links = sys->links;
    const int nl = k->nl, nn = k->nn;
    const double rho = sys->env.water_density, g = sys->env.gravity;
    if (k->nv > 0 && (!yv || !thdd))
        return TS_EINVAL;
    if (!u)
        u = k->uzero;
    memcpy(k->r, r, 3 * (size_t)nn * sizeof(double));
    memcpy(k->rd, v, 3 * (size_t)nn * sizeof(double));
    /* The vehicles' kinematics (attitude from yv, joint at their node),
     * which place the points P their child cables start from. */
    for (int i = 0; i < k->nv; i++)
        if (vehicle_kinematics(k, &k->veh[i], yv))
            return TS_CHART;
    /* A towing vehicle: the tow inputs move the points its cables start
     * from relative to the body (the same code as ts_kernel_eval: the
     * sparse model differences its input columns through this residual). */
    if (k->root >= 0)
        root_tow_inputs(k, &k->veh[k->root], u);
    /* Directions and strains from the positions: n = d / |d|, the strain
     * of an elastic link |d| / l - 1 (it sets only the bending lengths
     * here: the tensions are given). */
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        const double *rp = L->up_body >= 0 ? k->ur + 3 * l : r + 3 * L->upper;
        const double *rk = r + 3 * L->lower;
        double d[3] = {rk[0] - rp[0], rk[1] - rp[1], rk[2] - rp[2]};
        double len = v3_norm(d);
        if (!(len > 0))
            return TS_ESINGULAR;
        for (int j = 0; j < 3; j++)
            k->n[3 * l + j] = d[j] / len;
        k->strain[l] = L->elastic ? len / L->length - 1.0 : 0.0;
        k->t[l] = t[l];
    }
    assemble(k);
    memset(R, 0, 3 * sizeof(double));
    for (int i = 1; i < nn; i++) {
        double ia[3] = {a[3 * i] + k->afr[3 * i], a[3 * i + 1] +
                        k->afr[3 * i + 1], a[3 * i + 2] + k->afr[3 * i + 2]};
        sym3_mul(k->M + 6 * i, ia, R + 3 * i);
        v3_axpy(-1.0, k->Q + 3 * i, R + 3 * i);
    }
    for (int l = 0; l < nl; l++) {
        const ts_link *L = &links[l];
        v3_axpy(t[l], k->n + 3 * l, R + 3 * L->lower);
        if (L->upper > 0 && L->up_body < 0)
            v3_axpy(-t[l], k->n + 3 * l, R + 3 * L->upper);
    }
    /* Vehicles: the body's equations about A in body axes, r6 = M6 (a_A,
     * alpha) - G - sum_P J_P^T t n (its child cables at their points P,
     * their ends' masses and loads in M6 and G), the translational part
     * (the joint force, R r6[0..2]) added to its node's row, the
     * rotational part its own rows; then the controller's rates. */
    double *Rv = R + 3 * nn, *cdot = R + 3 * nn + 3 * k->nv;
    for (int i = 0; i < k->nv; i++) {
        veh *V = &k->veh[i];
        vehicle_loads(k, V, yv, u, rho, g);
        const tsi_vehicle_state *st = &V->st;
        double aA[3], nu[6], kap[3], fr[3], am[3], r6[6];
        for (int j = 0; j < 3; j++)
            aA[j] = a[3 * V->node + j] + k->afr[3 * V->node + j];
        mat3_tmul(st->R, aA, nu);
        tsi_rate_kappa(yv + V->qoff, yv + k->nq + V->qoff, kap);
        tsi_vehicle_frame_alpha(st, k->frame.turn_rate, k->frame.turn_accel,
                                fr);
        mat3_tmul(st->R, fr, am);
        mat3_mul(st->E, thdd + 3 * i, nu + 3);
        for (int j = 0; j < 3; j++)
            nu[3 + j] += kap[j] + am[j];
        for (int a6 = 0; a6 < 6; a6++) {
            r6[a6] = -V->G[a6];
            for (int b = 0; b < 6; b++)
                r6[a6] += V->M6[6 * a6 + b] * nu[b];
        }
        const ts_node *nd = &sys->nodes[V->node];
        for (int c = nd->child_begin; c < nd->child_end; c++) {
            int l = sys->child_links[c];
            double lever[3], f[3], m[3];
            link_lever(V, &links[l], lever);
            mat3_tmul(st->R, k->n + 3 * l, f);
            for (int j = 0; j < 3; j++)
                f[j] *= t[l];
            v3_cross(lever, f, m);
            for (int j = 0; j < 3; j++) {
                r6[j] -= f[j];
                r6[3 + j] -= m[j];
            }
        }
        double Fj[3];
        mat3_mul(st->R, r6, Fj);
        v3_axpy(1.0, Fj, R + 3 * V->node);
        for (int j = 0; j < 3; j++)
            Rv[3 * i + j] = r6[3 + j];
        control_rates(V, cdot);
    }
    return TS_OK;
}

void tsi_kernel_vehicle_mass(const ts_kernel *k, int v, double Mv[36])
{
    /* r6 = M6 (R^T a_i, E thdd + ...): d r6 / d(a_i, thdd) = M6 diag(R^T,
     * E); the translational rows go to M as R r6[0..2]. */
    const veh *V = &k->veh[v];
    const double *Rm = V->st.R, *E = V->st.E;
    double T[36];
    for (int a6 = 0; a6 < 6; a6++)
        for (int c = 0; c < 3; c++) {
            double x = 0, y = 0;
            for (int b = 0; b < 3; b++) {
                x += V->M6[6 * a6 + b] * Rm[3 * c + b];  /* (R^T)_{bc} */
                y += V->M6[6 * a6 + 3 + b] * E[3 * b + c];
            }
            T[6 * a6 + c] = x;
            T[6 * a6 + 3 + c] = y;
        }
    for (int c = 0; c < 6; c++) {
        for (int a3 = 0; a3 < 3; a3++) {
            Mv[6 * a3 + c] = Rm[3 * a3] * T[c] + Rm[3 * a3 + 1] * T[6 + c] +
                             Rm[3 * a3 + 2] * T[12 + c];
            Mv[6 * (3 + a3) + c] = T[6 * (3 + a3) + c];
        }
    }
}

void tsi_kernel_link_point(const ts_kernel *k, int l, const double n[3],
                           double pg[3], double pm[3])
{
    const ts_link *L = &k->sys->links[l];
    const veh *V = &k->veh[k->node_veh[L->upper]];
    const double *R = V->st.R, *E = V->st.E;
    double lever[3], rho[3], x[3], RE[9], nb[3];
    link_lever(V, L, lever);
    mat3_mul(R, lever, rho);
    v3_cross(rho, n, x);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            RE[3 * i + j] = R[3 * i] * E[j] + R[3 * i + 1] * E[3 + j] +
                            R[3 * i + 2] * E[6 + j];
    mat3_tmul(RE, x, pg);
    mat3_tmul(R, n, nb);
    v3_cross(lever, nb, pm);
    for (int j = 0; j < 3; j++)
        pm[j] = -pm[j];
}

void tsi_kernel_vehicle_layout(const ts_kernel *k, int v, tsi_vehicle_layout *lay)
{
    const veh *V = &k->veh[v];
    lay->node = V->node;
    lay->qoff = V->qoff;
    lay->c0 = -1;
    lay->nc = 0;
    lay->in0 = -1;
    lay->nin = 0;
    int cmin = k->nc, cmax = -1, imin = k->nin, imax = -1;
    for (int l = 0; l < V->d->nloops; l++) {
        int x[3] = {V->xi_off[l], V->in_loop[l], V->in_sp[l]};
        if (x[0] >= 0) {
            cmin = x[0] < cmin ? x[0] : cmin;
            cmax = x[0] > cmax ? x[0] : cmax;
        }
        for (int j = 1; j < 3; j++)
            if (x[j] >= 0) {
                imin = x[j] < imin ? x[j] : imin;
                imax = x[j] > imax ? x[j] : imax;
            }
    }
    for (int c = 0; c < V->d->ncomponents; c++) {
        if (V->act_off[c] >= 0) {
            cmin = V->act_off[c] < cmin ? V->act_off[c] : cmin;
            cmax = V->act_off[c] > cmax ? V->act_off[c] : cmax;
        }
        if (V->in_surf[c] >= 0) {
            imin = V->in_surf[c] < imin ? V->in_surf[c] : imin;
            imax = V->in_surf[c] > imax ? V->in_surf[c] : imax;
        }
    }
    if (V->root) {
        /* A towing vehicle: its speed controller's integrator, and its
         * propulsion inputs (thrust, force, moment, set speed). */
        int x[3] = {V->spd_off, V->in_prop, V->in_spd};
        if (x[0] >= 0) {
            cmin = x[0] < cmin ? x[0] : cmin;
            cmax = x[0] > cmax ? x[0] : cmax;
        }
        int last = x[2] >= 0 ? x[2] : x[1] + TSI_NPROP - 1;
        imin = x[1] < imin ? x[1] : imin;
        imax = last > imax ? last : imax;
    }
    if (cmax >= 0) {
        lay->c0 = cmin;
        lay->nc = cmax - cmin + 1;
    }
    if (imax >= 0) {
        lay->in0 = imin;
        lay->nin = imax - imin + 1;
    }
    lay->out0 = 0;
    for (int u = 0; u < v; u++)
        lay->out0 += OUT_MEASURES + k->veh[u].d->nloops + nsurfaces(&k->veh[u]);
    lay->nout = OUT_MEASURES + V->d->nloops + nsurfaces(V);
}

const double *tsi_kernel_mass(const ts_kernel *k) { return k->M; }

const double *ts_kernel_positions(const ts_kernel *k) { return k->r; }
const double *ts_kernel_velocities(const ts_kernel *k) { return k->rd; }
const double *ts_kernel_tensions(const ts_kernel *k) { return k->t; }
const double *ts_kernel_directions(const ts_kernel *k) { return k->n; }
const double *ts_kernel_rel_accelerations(const ts_kernel *k)
{
    return k->rdd;
}
const double *ts_kernel_loads(const ts_kernel *k) { return k->Q; }

double ts_kernel_tow_force(const ts_kernel *k, double F[3])
{
    const ts_system *sys = k->sys;
    double M0a[3];
    if (k->root >= 0) {
        /* The links leaving the towing vehicle's tow point: each its
         * tension and the half link lumped there (its loads less its
         * mass times its acceleration), Buckham's half of link 1. */
        const ts_node *n0 = &sys->nodes[0];
        v3_set(F, 0, 0, 0);
        for (int c = n0->child_begin; c < n0->child_end; c++) {
            int l = sys->child_links[c];
            sym3_mul(k->uM + 6 * l, k->ua + 3 * l, M0a);
            for (int j = 0; j < 3; j++)
                F[j] += k->t[l] * k->n[3 * l + j] + k->uQ[3 * l + j] -
                        M0a[j];
        }
        return v3_norm(F);
    }
    sym3_mul(k->M, k->a, M0a);
    for (int j = 0; j < 3; j++)
        F[j] = k->Q[j] - M0a[j];
    const ts_node *n0 = &sys->nodes[0];
    for (int c = n0->child_begin; c < n0->child_end; c++) {
        int l = sys->child_links[c];
        v3_axpy(k->t[l], k->n + 3 * l, F);
    }
    return v3_norm(F);
}

double ts_kernel_unbalanced(const ts_kernel *k, double *scale)
{
    double worst = 0.0, big = 0.0;
    for (int i = 1; i < k->nn; i++) {
        double f[3];
        sym3_mul(k->M + 6 * i, k->rdd + 3 * i, f);
        double m = v3_norm(f);
        if (!(m <= worst))
            worst = m; /* NaN propagates */
        double q = v3_norm(k->Q + 3 * i);
        if (q > big)
            big = q;
    }
    for (int l = 0; l < k->nl; l++)
        if (fabs(k->t[l]) > big)
            big = fabs(k->t[l]);
    /* A vehicle: M6 times its acceleration relative to the steady motion
     * in M, the force part and the moment part over the body's lever. */
    for (int v = 0; v < k->nv; v++) {
        const veh *V = &k->veh[v];
        double ar[3], af[3], r6[6], x6[6];
        const double *rdd = k->rdd + 3 * V->node;
        tsi_vehicle_frame_alpha(&V->st, k->frame.turn_rate,
                                k->frame.turn_accel, af);
        for (int j = 0; j < 3; j++)
            af[j] = V->alpha_m[j] - af[j];
        mat3_tmul(V->st.R, rdd, ar);
        mat3_tmul(V->st.R, af, x6 + 3);
        v3_copy(ar, x6);
        for (int i = 0; i < 6; i++) {
            r6[i] = 0;
            for (int j = 0; j < 6; j++)
                r6[i] += V->M6[6 * i + j] * x6[j];
        }
        double m = fmax(v3_norm(r6), v3_norm(r6 + 3) / V->lever);
        if (!(m <= worst))
            worst = m;
        big = fmax(big, fmax(V->mass * k->sys->env.gravity,
                             v3_norm(V->Fj)));
    }
    if (scale)
        *scale = big;
    return worst;
}

/* Inertial velocity of a point at r moving at rd relative to M. */
static void inertial_velocity(const ts_frame *f, const double r[3],
                              const double rd[3], double v[3])
{
    v[0] = f->speed - f->turn_rate * r[1] + rd[0];
    v[1] = f->turn_rate * r[0] + rd[1];
    v[2] = rd[2];
}

double ts_kernel_kinetic_energy(const ts_kernel *k)
{
    /* Inertial velocity v = V e_x + Omega e_z x r + r'; the fluid's
     * added mass is counted with the nodal mass matrix. */
    double T = 0.0;
    for (int i = 1; i < k->nn; i++) {
        const double *r = k->r + 3 * i, *rd = k->rd + 3 * i;
        double v[3], Mv[3];
        inertial_velocity(&k->frame, r, rd, v);
        sym3_mul(k->M + 6 * i, v, Mv);
        T += 0.5 * v3_dot(v, Mv);
    }
    /* A vehicle: 1/2 nu^T M6 nu about A (rigid body, added mass and the
     * masses at its child cables' starting points), nu = (v_A, omega) in
     * body axes. */
    for (int v = 0; v < k->nv; v++) {
        const veh *V = &k->veh[v];
        double va[3], nu[6];
        inertial_velocity(&k->frame, V->st.rA, V->st.rdA, va);
        mat3_tmul(V->st.R, va, nu);
        v3_copy(V->st.om_b, nu + 3);
        for (int i = 0; i < 6; i++)
            for (int j = 0; j < 6; j++)
                T += 0.5 * nu[i] * V->M6[6 * i + j] * nu[j];
    }
    return T;
}

double ts_kernel_potential_energy(const ts_kernel *k)
{
    const ts_system *sys = k->sys;
    double U = 0.0, g = sys->env.gravity;
    for (int i = 1; i < k->nn; i++)
        U -= sys->nodes[i].mass * g * k->r[3 * i + 2];
    for (int v = 0; v < k->nv; v++) {
        const veh *V = &k->veh[v];
        double rG[3], rdG[3];
        tsi_vehicle_point(V->d, &V->st, V->d->mass_centre, rG, rdG);
        U -= V->mass * g * rG[2];
    }
    for (int l = 0; l < k->nl; l++) {
        const ts_link *L = &sys->links[l];
        if (L->up_body >= 0)
            U -= 0.5 * L->mass * g * k->ur[3 * l + 2];
        /* Strain energy 1/2 EA l e^2 while taut (e > 0): the potential
         * of the elastic part EA e of the tension, whatever the damping. */
        if (L->elastic && k->strain[l] > 0) {
            double e = k->strain[l];
            U += 0.5 * L->ea * L->length * e * e;
        }
        if (L->ei > 0)
            U += tsi_bending_energy(L->ei * k->bend_scale, L->length,
                                    sys->links[L->next].length, k->n + 3 * l,
                                    k->n + 3 * L->next);
    }
    return U;
}

void ts_direction_angles(const double n[3], double *theta1, double *theta2)
{
    double ny = n[1] > 1 ? 1 : (n[1] < -1 ? -1 : n[1]);
    /* + 0.0 turns a negative zero into zero for display. */
    *theta2 = asin(-ny) + 0.0;
    *theta1 = atan2(n[2], -n[0]) + 0.0;
}

/* Angles and rates of link l in its chart for direction n and rate nd. */
static void link_set(ts_kernel *k, int l, const double n[3],
                     const double nd[3], double *t1, double *t2, double *t1d,
                     double *t2d)
{
    double nh[3];
    if (k->charted[l])
        mat3_tmul(k->chart + 9 * l, n, nh);
    else
        v3_copy(n, nh);
    ts_direction_angles(nh, t1, t2);
    if (t1d) {
        double nn_[3], e1[3], e2[3], c2, s2;
        link_axes(k, l, *t1, *t2, nn_, e1, e2, &c2, &s2);
        *t1d = nd ? v3_dot(e1, nd) / c2 : 0.0;
        *t2d = nd ? v3_dot(e2, nd) : 0.0;
    }
}

/* Coordinates of link l for unit direction n, direction rate nd (NULL:
 * zero), strain e and strain rate ed (elastic links; ignored for rigid
 * ones). A link whose |cos theta2| would fall below threshold is first
 * moved to a chart centred on n. Returns 1 when re-charted. */
static int set_one_link(ts_kernel *k, int l, const double n[3],
                        const double nd[3], double e, double ed,
                        double threshold, double y[])
{
    const int o = k->off[l], nq = k->nq;
    if (k->sys->links[l].elastic) {
        y[o + 2] = e;
        y[nq + o + 2] = ed;
    }
    double t1, t2, t1d, t2d;
    int moved = 0;
    link_set(k, l, n, nd, &t1, &t2, &t1d, &t2d);
    if (fabs(cos(t2)) < threshold) {
        tsi_chart_centred(n, k->chart + 9 * l);
        k->charted[l] = 1;
        link_set(k, l, n, nd, &t1, &t2, &t1d, &t2d);
        moved = 1;
    }
    y[o] = t1;
    y[o + 1] = t2;
    y[nq + o] = t1d;
    y[nq + o + 1] = t2d;
    return moved;
}

int ts_kernel_set_shape(ts_kernel *k, const double n[], const double strain[],
                        const double ndot[], const double strain_rate[],
                        double threshold, double y[])
{
    int moved = 0;
    for (int l = 0; l < k->nl; l++)
        moved += set_one_link(k, l, n + 3 * l, ndot ? ndot + 3 * l : NULL,
                              strain ? strain[l] : 0.0,
                              strain_rate ? strain_rate[l] : 0.0, threshold,
                              y);
    return moved;
}

int tsi_kernel_set_link(ts_kernel *k, int l, const double d[3],
                        const double ddot[3], double threshold, double y[])
{
    const ts_link *L = &k->sys->links[l];
    double len = v3_norm(d), n[3], nd[3], along = 0.0;
    for (int j = 0; j < 3; j++)
        n[j] = d[j] / len;
    if (ddot) {
        along = v3_dot(n, ddot);
        for (int j = 0; j < 3; j++)
            nd[j] = (ddot[j] - along * n[j]) / len;
    }
    return set_one_link(k, l, n, ddot ? nd : NULL, len / L->length - 1.0,
                        along / L->length, threshold, y);
}

int ts_kernel_set_links(ts_kernel *k, const double d[], const double ddot[],
                        double threshold, double y[])
{
    int moved = 0;
    for (int l = 0; l < k->nl; l++)
        moved += tsi_kernel_set_link(k, l, d + 3 * l,
                                     ddot ? ddot + 3 * l : NULL, threshold, y);
    return moved;
}

int ts_kernel_set_directions(ts_kernel *k, const double n[],
                             const double ndot[], double threshold,
                             double y[])
{
    return ts_kernel_set_shape(k, n, NULL, ndot, NULL, threshold, y);
}

/* Direction and direction rate of rigid link l for state y. */
static void link_dir_rate(const ts_kernel *k, int l, const double y[],
                          double n[3], double nd[3])
{
    const int o = k->off[l], nq = k->nq;
    double e1[3], e2[3], c2, s2;
    link_axes(k, l, y[o], y[o + 1], n, e1, e2, &c2, &s2);
    for (int j = 0; j < 3; j++)
        nd[j] = c2 * y[nq + o] * e1[j] + y[nq + o + 1] * e2[j];
}

/* 1-2-3 angles of a rotation R = R1 R2 R3 (regular where cos theta2 is
 * not 0). */
static void angles123(const double R[9], double th[3])
{
    double s2 = R[2] > 1 ? 1 : (R[2] < -1 ? -1 : R[2]);
    th[0] = atan2(-R[5], R[8]);
    th[1] = asin(s2);
    th[2] = atan2(-R[1], R[0]);
}

/* Vehicle v's angles and rates in its chart for attitude R (body to M)
 * and angular velocity om (relative to M, body axes; NULL: zero); a chart
 * whose cos theta2 would fall below threshold is first centred on R (the
 * angles then are 0). Returns 1 when re-charted. */
static int vehicle_set(ts_kernel *k, int v, const double R[9],
                       const double om[3], double threshold, double y[])
{
    veh *V = &k->veh[v];
    double Rc[9], th[3], thd[3] = {0, 0, 0};
    static const double zero[3] = {0, 0, 0};
    int moved = 0;
    for (int i = 0; i < 3; i++) /* Rc = chart^T R */
        for (int j = 0; j < 3; j++)
            Rc[3 * i + j] = V->chart[i] * R[j] + V->chart[3 + i] * R[3 + j] +
                            V->chart[6 + i] * R[6 + j];
    angles123(Rc, th);
    if (V->dof == 3) {
        /* A surface ship: its yaw alone, in the identity chart. */
        th[0] = th[1] = 0.0;
        tsi_rates_from_omega(th, om ? om : zero, thd);
        y[V->qoff] = th[2];
        y[k->nq + V->qoff] = thd[2];
        return 0;
    }
    if (!(fabs(cos(th[1])) >= threshold)) {
        memcpy(V->chart, R, sizeof V->chart);
        V->charted = 1;
        th[0] = th[1] = th[2] = 0.0;
        moved = 1;
    }
    tsi_rates_from_omega(th, om ? om : zero, thd);
    for (int j = 0; j < 3; j++) {
        y[V->qoff + j] = th[j];
        y[k->nq + V->qoff + j] = thd[j];
    }
    return moved;
}

/* Attitude (body to M) and angular velocity relative to M (body axes) of
 * vehicle v in state y. */
static void vehicle_get(const ts_kernel *k, int v, const double y[],
                        double R[9], double om[3])
{
    const veh *V = &k->veh[v];
    double R123[9], E[9], th[3], thd[3];
    vehicle_angles(k, V, y, th, thd);
    tsi_rot123(th, R123);
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            R[3 * i + j] = V->chart[3 * i] * R123[j] +
                           V->chart[3 * i + 1] * R123[3 + j] +
                           V->chart[3 * i + 2] * R123[6 + j];
    if (om) {
        tsi_rate_matrix(th, E);
        mat3_mul(E, thd, om);
    }
}

int ts_kernel_set_vehicle(ts_kernel *k, int v, const double R[9],
                          const double omega[3], double threshold, double y[])
{
    return vehicle_set(k, v, R, omega, threshold, y);
}

void ts_kernel_get_vehicle(const ts_kernel *k, int v, const double y[],
                           double R[9], double omega[3])
{
    vehicle_get(k, v, y, R, omega);
}

int ts_kernel_rechart(ts_kernel *k, double y[], double threshold)
{
    int nq = k->nq, moved = 0;
    for (int l = 0; l < k->nl; l++) {
        const int o = k->off[l];
        if (fabs(cos(y[o + 1])) >= threshold)
            continue;
        double n[3], nd[3];
        link_dir_rate(k, l, y, n, nd);
        tsi_chart_centred(n, k->chart + 9 * l);
        k->charted[l] = 1;
        link_set(k, l, n, nd, &y[o], &y[o + 1], &y[nq + o], &y[nq + o + 1]);
        moved++;
    }
    for (int v = 0; v < k->nv; v++) {
        if (k->veh[v].dof == 3 || fabs(cos(y[k->veh[v].qoff + 1])) >= threshold)
            continue;
        double R[9], om[3];
        vehicle_get(k, v, y, R, om);
        moved += vehicle_set(k, v, R, om, INFINITY, y);
    }
    return moved;
}

int ts_kernel_reset_charts(ts_kernel *k, double y[], double threshold)
{
    int nq = k->nq, left = 0;
    for (int l = 0; l < k->nl; l++) {
        if (!k->charted[l])
            continue;
        const int o = k->off[l];
        double n[3], nd[3], t1, t2;
        link_dir_rate(k, l, y, n, nd);
        ts_direction_angles(n, &t1, &t2);
        if (fabs(cos(t2)) < threshold) {
            left++;
            continue;
        }
        k->charted[l] = 0;
        link_set(k, l, n, nd, &y[o], &y[o + 1], &y[nq + o], &y[nq + o + 1]);
    }
    for (int v = 0; v < k->nv; v++) {
        veh *V = &k->veh[v];
        if (!V->charted)
            continue;
        double R[9], om[3], th[3];
        vehicle_get(k, v, y, R, om);
        angles123(R, th);
        if (fabs(cos(th[1])) < threshold) {
            left++;
            continue;
        }
        memset(V->chart, 0, sizeof V->chart);
        V->chart[0] = V->chart[4] = V->chart[8] = 1.0;
        V->charted = 0;
        vehicle_set(k, v, R, om, 0.0, y);
    }
    return left;
}

void ts_kernel_vehicle_result(const ts_kernel *k, int v, ts_vehicle_result *r)
{
    const veh *V = &k->veh[v];
    const ts_vehicle *d = V->d;
    double ypr[3], rd[3];
    memset(r, 0, sizeof *r);
    r->body = V->body;
    memcpy(r->R, V->st.R, sizeof r->R);
    tsi_ypr_from_rot(V->st.R, ypr);
    r->yaw = ypr[0];
    r->pitch = ypr[1];
    r->roll = ypr[2];
    const double *w = V->st.wO_b;
    r->speed = v3_norm(w);
    r->alpha = atan2(w[2], w[0]) + 0.0;
    r->beta = r->speed > 0 ? asin(w[1] / r->speed) + 0.0 : 0.0;
    v3_copy(V->st.rO, r->origin);
    tsi_vehicle_point(d, &V->st, d->mass_centre, r->mass_centre, rd);
    v3_copy(V->st.om_rel_b, r->omega);
    r->submerged = V->st.frac;
    v3_copy(V->Fj, r->joint_force);
    if (V->root) {
        r->towing = 1;
        r->dof = V->dof;
        if (V->dof == 3)
            memcpy(r->held, V->held, sizeof r->held);
        ts_kernel_tow_force(k, r->joint_force);
        r->thrust = V->thrust;
        r->power = V->thrust * w[0];
        r->track_speed = k->frame.speed;
        r->turn_rate = k->frame.turn_rate;
    }
    r->ncomponents = d->ncomponents;
    memcpy(r->delta, V->delta, sizeof r->delta);
    const ts_system *sys = k->sys;
    tsi_vehicle_hydro(d, V->ws, sys->env.water_density, V->st.frac, w,
                      V->st.om_b, V->delta, r->hydro_force, r->hydro_moment,
                      r->load);
    /* The masts' and tanks' entries: their static loads (not part of
     * hydro_force). */
    double Fm[3], Mm[3];
    tsi_vehicle_statics(d, sys->env.water_density, sys->env.gravity, &V->st,
                        V->delta, Fm, Mm, r->load);
    /* The Munk moment: the -v x p part of the loads, with gravity off. */
    double G[6];
    tsi_vehicle_loads(d, V->ws, V->mass, sys->env.water_density, 0.0, &V->st,
                      V->delta, G, r->munk);
    r->nloops = d->nloops;
    for (int l = 0; l < d->nloops; l++) {
        r->loop_error[l] = tsi_loop_error(&d->loop[l], V->meas, V->sp[l]);
        r->loop_output[l] = V->out[l];
    }
}

int tsi_kernel_vehicle_pull(ts_kernel *k, int v, const double y[],
                            const double rA[3], double F[3])
{
    veh *V = &k->veh[v];
    static const double zero[3] = {0, 0, 0};
    double afr[3], ab[3], h[3], th[3], thd[3];
    vehicle_angles(k, V, y, th, thd);
    tsi_vehicle_kinematics(V->d, V->chart, th, zero,
                           k->frame.turn_rate, rA, zero, &V->st);
    tsi_vehicle_flow(&k->frame, V->d, &V->st);
    if (!(fabs(V->st.c2) >= TS_CHART_MIN))
        return TS_CHART;
    vehicle_own_loads(k, V, y, k->uzero, k->sys->env.water_density,
                      k->sys->env.gravity);
    /* At rest in the frame the joint accelerates with the frame, afr,
     * and the body does not turn relative to it: the joint force on the
     * body is M6_tt R^T afr - G_t (body axes), the pull its opposite. */
    tsi_frame_accel(&k->frame, rA, zero, afr);
    mat3_tmul(V->st.R, afr, ab);
    for (int i = 0; i < 3; i++)
        h[i] = V->G[i] - (V->M6[6 * i] * ab[0] + V->M6[6 * i + 1] * ab[1] +
                          V->M6[6 * i + 2] * ab[2]);
    mat3_mul(V->st.R, h, F);
    return isfinite(F[0] + F[1] + F[2]) ? TS_OK : TS_EDOMAIN;
}

void tsi_kernel_vehicle_lever(const ts_kernel *k, int v, const double y[],
                              int link, double off[3])
{
    const veh *V = &k->veh[v];
    double R[9], rho[3];
    ts_kernel_get_vehicle(k, v, y, R, NULL);
    link_lever(V, &k->sys->links[link], rho);
    mat3_mul(R, rho, off);
}
