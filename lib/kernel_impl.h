/* kernel_impl.h: what lib/kernel.c shares with the modules above it
 * (internal). */
#ifndef TOWSTAB_KERNEL_IMPL_H
#define TOWSTAB_KERNEL_IMPL_H

#include "towstab/kernel.h"
#include "vehicle.h"

/* Name of tow input j < TS_NINPUT ("tow.surge", ...), NULL outside. */
const char *tsi_tow_input_name(int j);

/* The flow past a vehicle whose kinematics st holds (tsi_vehicle_kinematics):
 * st->wO_b, the velocity of its origin relative to the water (frame f and
 * its current), and st->frac, its submerged fraction: the circular
 * segment of a horizontal cylinder of the vehicle's surface_diameter
 * centred at its buoyancy centre (1 below one radius; a step at z = 0
 * without a diameter). */
void tsi_vehicle_flow(const ts_frame *f, const ts_vehicle *d,
                      tsi_vehicle_state *st);

#endif
