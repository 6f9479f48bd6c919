/* towstab/scene.h: scene files (YAML) -> ts_system plus a list of analyses.
 *
 * The format is documented in doc/scene-format.md. Every quantity may carry
 * a unit (towstab/units.h). Every error names the key, the line and what was
 * expected, e.g. "cables[1].length (line 14): must be > 0 m, got -3 m".
 */
#ifndef TOWSTAB_SCENE_H
#define TOWSTAB_SCENE_H

#include <stddef.h>

#include "towstab/error.h"
#include "towstab/system.h"
#include "towstab/units.h"

#ifdef __cplusplus
extern "C" {
#endif

/* One option of an analysis entry, kept as text for the command that runs
 * it to interpret (with units) and to refuse when unknown. */
typedef struct ts_scene_option {
    char key[TS_NAME_MAX];
    char *value;            /* scalar text; owned by the scene */
    int line;
} ts_scene_option;

typedef struct ts_scene_analysis {
    char type[TS_NAME_MAX]; /* "equilibrium", ... */
    int line;
    int noptions;
    ts_scene_option *options;
} ts_scene_analysis;

/* A value set over a scene's text (ts_scene_set). */
typedef struct ts_scene_setting {
    char *key;              /* "cables[0].length" (owned) */
    char *value;            /* YAML text (owned); NULL: the key removed */
} ts_scene_setting;

typedef struct ts_scene {
    char path[512];         /* as given to ts_scene_load (a longer path is
                               refused with TS_EINVAL), "" for strings */
    ts_system *system;      /* built (ts_system_build has run) */
    int nanalyses;
    ts_scene_analysis *analyses;
    ts_scene_analysis *design; /* the `design` section (type "design"; a
                               list's items are options of the same key,
                               in order), NULL when absent: the settings
                               of `towstab design` (doc/design.md) */
    char *text;             /* the YAML text read, text_len bytes and a
                               NUL (owned): what a report shows */
    size_t text_len;
    int nsettings;          /* the values set over the text, in the order
                               applied (ts_scene_set); 0 for a file */
    ts_scene_setting *settings;
    /* tow.speed and tow.turn_rate as the scene wrote them ("5 knot";
     * "" when absent or longer than the buffer): for legends and labels,
     * which show quantities as the user wrote them. */
    char speed_text[TS_NAME_MAX];
    char turn_rate_text[TS_NAME_MAX];
} ts_scene;

/* Read and build a scene from a file; path "-" reads standard input to
 * its end (messages then name "standard input"). On failure returns NULL,
 * with the error in err (TS_EIO, TS_ESCENE, TS_EUNIT or TS_EINVAL). */
TS_API ts_scene *ts_scene_load(const char *path, const ts_units *units,
                               ts_err *err);

/* The same from a buffer of `len` bytes (need not be NUL-terminated);
 * `name` is used in messages. */
TS_API ts_scene *ts_scene_parse(const char *text, size_t len, const char *name,
                                const ts_units *units, ts_err *err);

/* A new scene: the text of `scene` read again with its settings and then
 * keys[i] set to values[i] (i < n), e.g. for a sweep. A key is a path of
 * the scene format (doc/scene-format.md, "Setting values"): names joined
 * by '.', a list entry selected by its index from 0 or by its name:
 * "tow.speed", "cables[0].length", "cables[armour].links",
 * "bodies[fish].mass", "analyses[1].t_end", "tow.point[2]". A value is
 * YAML text, with units as in a file ("5 knot", "[0, 0, -5 m]"); NULL
 * removes the key. An absent key is added, and the scene is then checked
 * as a file is, so a key the format does not have is refused by name; a
 * key set again replaces its earlier setting. Messages name the key, and
 * the line of the value replaced (or of the mapping added to). The new
 * scene has the same path and text, and the settings so far. NULL on
 * failure (err: TS_EINVAL for a key that selects nothing or a value that
 * is not YAML, else the scene's codes); `scene` is not changed. */
TS_API ts_scene *ts_scene_set(const ts_scene *scene, int n,
                              const char *const keys[],
                              const char *const values[],
                              const ts_units *units, ts_err *err);

/* Free a scene and its system. ts_scene_free(NULL) does nothing. */
TS_API void ts_scene_free(ts_scene *scene);

/* The value of option `key` of an analysis, NULL if absent. */
TS_API const ts_scene_option *
ts_scene_analysis_option(const ts_scene_analysis *a, const char *key);

#ifdef __cplusplus
}
#endif
#endif
