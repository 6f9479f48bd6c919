/* dlmodule_build.c: where this build's modules are, for the programs of
 * the build tree linked to the static archive (the tests and benchmarks;
 * lib/meson.build compiles it into each of them, with
 * TSI_MODULE_BUILD_DIR). Linked so, a program's file is its own, and the
 * modules are not beside it (lib/dlmodule.h); the library itself never
 * defines this name. */
#include "dlmodule.h"

const char *const tsi_module_build_dir = TSI_MODULE_BUILD_DIR;
