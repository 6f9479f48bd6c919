/* param_impl.h (private): the table of a scene's scalar keys, one row per
 * key: its SI unit, its lower limit and where it lives in the system.
 * Stated once, here, for the scene reader (lib/scene.c: the unit a value
 * is read in and the limit it is checked against) and for values by path
 * (lib/param.c: ts_param_set, ts_param_unit), so that a key's unit and
 * limit cannot differ between a scene file and a sweep or design. */
#ifndef TOWSTAB_LIB_PARAM_IMPL_H
#define TOWSTAB_LIB_PARAM_IMPL_H

#include <stddef.h>

/* How a row's value is stored. */
enum {
    TSI_KEY_PLAIN = 0,   /* a double at the offset */
    TSI_KEY_WEIGHT,      /* weight: mass = value / g */
    TSI_KEY_WET_WEIGHT,  /* weight in water: mass = value / g + rho volume */
    TSI_KEY_LINKS,       /* a whole number of links */
    TSI_KEY_VECTOR,      /* component of a 3-vector (x, y, z) */
    TSI_KEY_INERTIA      /* entry of an inertia [Ixx, Iyy, Izz, Ixy, Ixz,
                            Iyz] (xx, yy, zz, xy, xz, yz) */
};

typedef struct tsi_key {
    const char *key;
    const char *unit;  /* SI; "" where it follows from the entry (a
                          loop's gains: from what it measures) */
    double min;        /* lower limit, -INFINITY for none */
    int strict;        /* 1: value > min, 0: value >= min */
    int kind;
    size_t offset;     /* in the table's struct */
} tsi_key;

/* The tables: tow (ts_tow), environment (ts_environment), a cable
 * (ts_cable), a body (ts_body), a vehicle's own keys (ts_vehicle), its
 * loop (ts_loop), lifting surface, hull, bluff part, mast and ballast
 * tank (ts_component), and a towing vehicle's propulsion (ts_propulsion). */
typedef enum {
    TSI_KEYS_TOW = 0, TSI_KEYS_ENV, TSI_KEYS_CABLE, TSI_KEYS_BODY,
    TSI_KEYS_LOOP, TSI_KEYS_SURFACE, TSI_KEYS_VEHICLE, TSI_KEYS_HULL,
    TSI_KEYS_BLUFF, TSI_KEYS_PROPULSION, TSI_KEYS_MAST, TSI_KEYS_BALLAST
} tsi_keys;

/* The row of `key` in table t, NULL when the table has none. */
const tsi_key *tsi_key_find(tsi_keys t, const char *key);

/* The SI unit of a loop's "kp", "ki", "kd" or "setpoint": from what it
 * measures, a depth (depth 1: rad/m, rad/(m*s), rad*s/m, m) or an angle
 * (1, 1/s, s, rad). */
const char *tsi_loop_unit(int depth, const char *key);

#endif
