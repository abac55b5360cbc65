// SPDX-License-Identifier: MIT
/// @file compiler.h
/// @brief Compiler attributes of the core. Internal (not an installed header).
#ifndef SHADOWLEAN_CORE_COMPILER_H
#define SHADOWLEAN_CORE_COMPILER_H

/// Keeps a helper's locals out of its caller's frame (stack budget: the deepest chain runs
/// from sl_pipeline_feed through on_rot into detection and the tilt fit;
/// tests/core/build/stack_budget.py), or a rare path out of a hot loop.
#if defined(__GNUC__)
#define SL_NOINLINE __attribute__((noinline))
#else
#define SL_NOINLINE
#endif

#endif // SHADOWLEAN_CORE_COMPILER_H
