// SPDX-License-Identifier: MIT
/// @file port_clock.h
/// @brief The Linux port's clock, shared by the port modules.
///
/// The core never reads a clock; the port does, here, and passes `now_us` in.
#ifndef SHADOWLEAN_PORT_CLOCK_H
#define SHADOWLEAN_PORT_CLOCK_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/// Microseconds of CLOCK_MONOTONIC (arbitrary origin, never jumps). Cost: one vDSO call.
uint64_t slp_now_us(void);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_PORT_CLOCK_H
