/* report_time_impl.h: the keys of a time history's JSON object written
 * into an open object (internal; lib/jsonout.h), for the result's
 * document (lib/report_result.c) as for the trees of
 * towstab/report_time.h. */
#ifndef TOWSTAB_REPORT_TIME_IMPL_H
#define TOWSTAB_REPORT_TIME_IMPL_H

#include "jsonout.h"
#include "towstab/report_time.h"

/* The keys of a time history's object (towstab/report_time.h), emitted
 * into an open object: ts_report_channels_json's ("t", "outputs"), those
 * ts_report_history_full adds ("nodes", "tensions", "energy",
 * "vehicle_outputs", "tow_force", "frame"), and ts_report_extremes_json's
 * ("max" ... "from_s"). */
void tsi_report_channels_keys(tsi_json *w, const ts_system *sys,
                              const ts_history *h, int n,
                              const ts_output outs[]);
void tsi_report_full_keys(tsi_json *w, const ts_system *sys,
                          const ts_history *h);
void tsi_report_extremes_keys(tsi_json *w, const ts_extremes *e);

#endif
