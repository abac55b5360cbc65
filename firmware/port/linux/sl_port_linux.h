// SPDX-License-Identifier: MIT
/// @file sl_port_linux.h
/// @brief Linux port helpers shared by the port modules (clock).
///
/// The core never reads a clock; the port does, here, and passes `now_us` in.
#ifndef SHADOWLEAN_SL_PORT_LINUX_H
#define SHADOWLEAN_SL_PORT_LINUX_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// Microseconds of CLOCK_MONOTONIC (arbitrary origin, never jumps). Cost: one vDSO call.
uint64_t sl_port_now_us(void);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_PORT_LINUX_H
