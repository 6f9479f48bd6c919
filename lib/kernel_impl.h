/* kernel_impl.h: what lib/kernel.c shares with the modules above it
 * (internal). */
#ifndef TOWSTAB_KERNEL_IMPL_H
#define TOWSTAB_KERNEL_IMPL_H

/* Name of tow input j < TS_NINPUT ("tow.surge", ...), NULL outside. */
const char *tsi_tow_input_name(int j);

#endif
