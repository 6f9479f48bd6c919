/* tscene.h: loading a scene in a test program (a file or YAML text): one
 * checked line, PASS or FAIL with the reader's message; and a system's
 * equilibrium solved with its kernel. Needs tcheck.h and <string.h>. */
#ifndef TOWSTAB_TSCENE_H
#define TOWSTAB_TSCENE_H

#include <stdio.h>
#include <string.h>

#include "towstab/equilibrium.h"
#include "towstab/kernel.h"
#include "towstab/scene.h"
#include "towstab/units.h"

static inline ts_scene *tscene_load(const ts_units *u, const char *path)
{
    ts_err err = {0};
    ts_scene *s = u ? ts_scene_load(path, u, &err) : NULL;
    CHECK(s != NULL, "%s loads (%s)", path, s ? "ok" : err.msg);
    return s;
}

/* A scene from YAML text (named "test"); NULL after printing the
 * reader's message. */
static inline ts_scene *tscene_parse(const ts_units *u, const char *yaml)
{
    ts_err err = {0};
    ts_scene *s = ts_scene_parse(yaml, strlen(yaml), "test", u, &err);
    if (!s)
        printf("scene: %s\n", err.msg);
    return s;
}

/* The units system of a test program; NULL after printing a FAIL line
 * (main returns 1 then). */
static inline ts_units *tscene_units(void)
{
    ts_err err = {0};
    ts_units *u = ts_units_alloc(&err);
    if (!u)
        printf("FAIL units: %s\n", err.msg);
    return u;
}

/* A solved equilibrium of a system with its kernel. */
typedef struct tscene_solved {
    ts_kernel *k;
    ts_equilibrium *eq;
} tscene_solved;

/* Solve sys's equilibrium by `method` into s (free with
 * tscene_solved_free, also on failure); the message printed on failure. */
static inline int tscene_solve(const ts_system *sys, tscene_solved *s,
                               ts_eq_method method)
{
    ts_err err = {0};
    ts_equilibrium_opts o;
    ts_equilibrium_opts_default(&o);
    o.method = method;
    s->k = ts_kernel_alloc(sys, &err);
    s->eq = s->k ? ts_equilibrium_alloc(sys, &err) : NULL;
    int rc = s->eq ? ts_equilibrium_solve(s->k, &o, s->eq, &err) : -1;
    if (rc != TS_OK)
        printf("  equilibrium: %s\n", err.msg);
    return rc;
}

static inline void tscene_solved_free(tscene_solved *s)
{
    ts_equilibrium_free(s->eq);
    ts_kernel_free(s->k);
}

#endif
