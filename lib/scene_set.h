/* scene_set.h: values set over a scene's YAML document before it is read
 * (internal to the scene module; towstab/scene.h, ts_scene_set).
 *
 * A key is a path of the scene format: names joined by '.', each name
 * optionally followed by selectors [i] (the i-th entry of a list, from 0)
 * or [NAME] (the entry of a list of mappings whose `name` is NAME):
 * "tow.speed", "cables[0].length", "cables[armour].links",
 * "bodies[fish].mass", "analyses[2].t_end", "tow.point[2]". A value is
 * YAML text: a scalar ("100 ft", "3.5", "true") or a flow collection
 * ("[0, 0, -5 m]"); NULL removes the key. A key that is absent is added
 * (with the mappings above it), so that the scene's own checks refuse a
 * key the format does not have, naming it, as in a file. A list entry
 * that does not exist is refused here. New nodes take the line of the
 * node they replace or of the mapping they join, so that messages point
 * into the file.
 */
#ifndef TOWSTAB_SCENE_SET_H
#define TOWSTAB_SCENE_SET_H

#include <yaml.h>

#include "towstab/error.h"

/* Set keys[i] to values[i], i = 0..n-1 in order, in doc. TS_OK, or
 * TS_EINVAL (a malformed key, a selector that matches nothing, a value
 * that is not YAML, removing a list entry) or TS_ENOMEM, with a message
 * that starts with the key. */
int tsi_scene_apply(yaml_document_t *doc, int n, const char *const keys[],
                    const char *const values[], ts_err *err);

/* "a scalar", "a list", "a mapping" or "an empty node" (scene.c). */
const char *tsi_scene_kind_name(const yaml_node_t *n);

#endif
