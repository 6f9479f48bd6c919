/* tscene.h: loading a scene in a test program (a file or YAML text): one
 * checked line, PASS or FAIL with the reader's message. Needs tcheck.h
 * and <string.h>. */
#ifndef TOWSTAB_TSCENE_H
#define TOWSTAB_TSCENE_H

#include <stdio.h>
#include <string.h>

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

#endif
