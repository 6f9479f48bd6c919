/* tscene.h: loading a scene in a test program, from a file or from YAML
 * text: one checked line, PASS or FAIL with the reader's message. Needs
 * tcheck.h. */
#ifndef TOWSTAB_TSCENE_H
#define TOWSTAB_TSCENE_H

#include <string.h>

#include "towstab/scene.h"

static inline ts_scene *tscene_load(const ts_units *u, const char *path)
{
    ts_err err = {0};
    ts_scene *s = u ? ts_scene_load(path, u, &err) : NULL;
    CHECK(s != NULL, "%s loads (%s)", path, s ? "ok" : err.msg);
    return s;
}

/* A scene from YAML text; its name in the messages is its first line. */
static inline ts_scene *tscene_parse(const ts_units *u, const char *yaml)
{
    ts_err err = {0};
    ts_scene *s = u ? ts_scene_parse(yaml, strlen(yaml), "test", u, &err)
                    : NULL;
    CHECK(s != NULL, "scene '%.*s' parses (%s)", (int)strcspn(yaml, "\n"),
          yaml, s ? "ok" : err.msg);
    return s;
}

#endif
