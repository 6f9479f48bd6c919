/* towstab/output.h: output channels, the named quantities an analysis
 * reports of a state (doc/manual.md, "Output conventions").
 *
 * A channel is named as the user writes it:
 *   <node>.x|y|z            a node's position in M (m): <node> a body's
 *                           name or <cable>.<k>, the lower end of link k
 *   <cable>.<k>.tension     link k's tension (N); <body>.tension is the
 *                           link ending at the body
 *   <cable>.<k>.strain      an elastic link's strain (1): its length over
 *                           its unstretched length, less 1
 *   <cable>.length          an elastic cable's stretched length (m)
 *   tow.force               the size of the force the towed system exerts
 *                           on the tow point (N): the top tension
 *   tow.force.x|y|z         its components in M (N)
 *   <node>.earth_x|earth_y  a node's horizontal position in the earth
 *                           frame E (m; towstab/track.h), also
 *                           tow.earth_x|earth_y for the tow point: only
 *                           in a simulation, which integrates M's track
 * The kinds are listed in ts_output_kind; a new kind (a vehicle's
 * attitude, say) is a new enumerator, a clause of ts_output_find and one
 * of ts_output_value. Every analysis that reports channels names them
 * with ts_output_find, so a name means one thing everywhere.
 */
#ifndef TOWSTAB_OUTPUT_H
#define TOWSTAB_OUTPUT_H

#include <stddef.h>

#include "towstab/error.h"
#include "towstab/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    TS_OUT_POSITION = 0,  /* node, comp 0..2 */
    TS_OUT_TENSION = 1,   /* link */
    TS_OUT_TOW_FORCE = 2, /* comp 0..2, or TS_OUT_MAGNITUDE */
    TS_OUT_STRAIN = 3,    /* link (elastic) */
    TS_OUT_LENGTH = 4,    /* cable (elastic): stretched length */
    TS_OUT_VEHICLE = 5,   /* a vehicle's depth, pitch, roll, yaw, loop
                             output or deflection: row `index` of the
                             kernel's outputs (ts_kernel_output_name),
                             found by ts_response_output_lookup with a
                             kernel, not by ts_output_find */
    TS_OUT_EARTH = 6      /* node (0: the tow point), comp 0 x, 1 y in the
                             earth frame: found by ts_output_find when
                             `kinds` has its bit (outside TS_OUT_ALL),
                             valued by ts_history_value */
} ts_output_kind;
#define TS_OUT_KINDS 5 /* the kinds ts_output_find knows */

/* Bits of the kinds an analysis reports (ts_output_names). */
#define TS_OUT_BIT(kind) (1 << (kind))
#define TS_OUT_ALL ((1 << TS_OUT_KINDS) - 1)

/* comp of the size of a vector output. */
#define TS_OUT_MAGNITUDE 3

#define TS_OUTPUT_NAME_MAX (2 * TS_NAME_MAX + 16)

/* An output channel. */
typedef struct ts_output {
    ts_output_kind kind;
    int node;      /* position: node index (>= 1) */
    int comp;      /* position: 0 x, 1 y, 2 z (M frame, z down); tow
                      force: the same, or TS_OUT_MAGNITUDE */
    int link;      /* tension, strain: link index */
    int cable;     /* length: cable index */
    int index;     /* vehicle: the output's row in ts_linear.Vy */
    char name[TS_OUTPUT_NAME_MAX]; /* canonical name, e.g. "sphere.z" */
    const char *unit;    /* a frequency response's gain: the quantity per
                            metre of tow-point motion ("m/m", "N/m") */
    const char *si_unit; /* the quantity's own: "m", "N", "1" */
} ts_output;

/* Parse a channel name (above) of one of the kinds in `kinds`
 * (TS_OUT_BIT bits; TS_OUT_ALL: any). Returns TS_OK or TS_EINVAL with a
 * message "output 'NAME': why; valid outputs: ..." that lists the valid
 * names of those kinds. A strain or length of a rigid cable, or of a link
 * starting at a point of a vehicle, is refused. */
TS_API int ts_output_find(const ts_system *sys, const char *name, int kinds,
                          ts_output *out, ts_err *err);

/* The valid names of the kinds in `kinds` (TS_OUT_BIT bits), compactly
 * ("cable.1 .. cable.19, sphere" per cable), into buf. */
TS_API void ts_output_names(const ts_system *sys, int kinds, char *buf,
                            size_t size);

/* 1 for a force (tension, tow force), whose extremes a run reports. */
TS_API int ts_output_is_force(const ts_output *out);

/* The channel's value in one state: node positions pos[3 nnodes] (m),
 * link tensions tens[nlinks] (N) and the force on the tow point
 * tow_force[3] (N), as the kernel reports them (towstab/kernel.h). NAN
 * when an array it needs is NULL or holds NAN (a linear run has no tow
 * force). sys may be NULL for positions, tensions and the tow force. */
TS_API double ts_output_value(const ts_system *sys, const ts_output *out,
                              const double pos[], const double tens[],
                              const double tow_force[]);

#ifdef __cplusplus
}
#endif
#endif
