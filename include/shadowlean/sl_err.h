// SPDX-License-Identifier: MIT
/// @file sl_err.h
/// @brief Error codes shared by every shadowlean module.
///
/// Convention (libcanard v4 / littlefs): functions return `sl_err_t`; `SL_OK` is zero and
/// every error is negative, starting at -2. Functions that return a size or a count use
/// `sl_ssize_t`: non-negative values are the result, negative values are `sl_err_t`.
///
/// Bytes that come from the radar or the bus are never asserted on: they are rejected,
/// counted in the module's `stats`, and the module resynchronises. `SL_ASSERT` is reserved
/// for caller bugs (NULL self, impossible state) and can be overridden before including
/// any shadowlean header (define `SL_ASSERT(x)` yourself, for example to a breakpoint).
#ifndef SHADOWLEAN_SL_ERR_H
#define SHADOWLEAN_SL_ERR_H

#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_config.h" // SL_CFG_USER_HEADER may define SL_ASSERT

#ifdef __cplusplus
extern "C" {
#endif

typedef enum sl_err {
    SL_OK = 0,
    SL_ERR_ARG = -2,       ///< a caller passed an invalid argument (NULL, out of range)
    SL_ERR_NEED_MORE = -3, ///< more input is needed before anything can be produced
    SL_ERR_MALFORMED = -4, ///< the input violates the format; it was counted and skipped
    SL_ERR_FULL = -5,      ///< a bounded buffer or queue is full; nothing was written
    SL_ERR_BUSY = -6,      ///< the port cannot take it now; try again later (never blocks)
    SL_ERR_PORT = -7,      ///< the port (OS, device) reported a failure
    SL_ERR_RANGE = -8,     ///< a value does not fit the target's documented range
    SL_ERR_STATE = -9,     ///< the call is not valid in the object's current state
    // Calibration blob (sl_calblob.h): one code per failed check.
    SL_ERR_CAL_SIZE = -10,      ///< blob truncated, or its size fields are inconsistent
    SL_ERR_CAL_MAGIC = -11,     ///< not a calibration blob (magic)
    SL_ERR_CAL_VERSION = -12,   ///< a blob format version this core does not read
    SL_ERR_CAL_CRC = -13,       ///< CRC-32 mismatch: the blob is corrupt
    SL_ERR_CAL_BOARD = -14,     ///< made for another board (name or identity hash)
    SL_ERR_CAL_AZIMUTHS = -15,  ///< azimuth count differs from the board's
    SL_ERR_CAL_VALUE = -16,     ///< a calibrated value is out of its range
    SL_ERR_CAL_WORKSPACE = -17, ///< cannot be read in place and no workspace was given
} sl_err_t;

/// Signed size: >= 0 is a count, < 0 is an `sl_err_t`.
typedef int32_t sl_ssize_t;

/// Borrowed view of bytes. The lifetime is documented by whoever hands it out.
typedef struct sl_bytes {
    const uint8_t *data;
    size_t size;
} sl_bytes_t;

/// A short, constant, human-readable name for an error code ("SL_ERR_ARG", ...).
/// Never NULL; unknown codes give "SL_ERR_?". Cost: O(1).
const char *sl_err_str(sl_err_t err);

/// @def SL_ASSERT(x)
/// Caller-bug check (NULL self, impossible state; never input data). Override it for the
/// whole build, core included, by defining it before any shadowlean header is read:
/// - in `sl_config_user.h` (tests/core/assert_user/ is a working example) (with `SL_CFG_USER_HEADER` defined; sl_config.h includes it
///   and this header includes sl_config.h), e.g.
///   `#define SL_ASSERT(x) do { if (!(x)) { board_fault(__FILE__, __LINE__); } } while (0)`
///   where board_fault() is the application's (it must not return into the core);
/// - or on the compiler command line (`-D'SL_ASSERT(x)=...'`), where the build tool allows
///   function-like definitions (CMake's compile definitions do not).
/// The core must see the same definition as the application (compile both with it).
/// Default: GCC and Clang trap (`__builtin_trap()`: `udf` on Arm, a HardFault the board's
/// handler reports). Other compilers (IAR, Arm Compiler 5, TASKING, MSVC ...) that define
/// no `SL_ASSERT` get an endless loop, which stops the caller where a debugger or the
/// watchdog sees it: define SL_ASSERT for them if that is not what the product wants.
#ifndef SL_ASSERT
#if defined(__GNUC__) || defined(__clang__)
#define SL_ASSERT(x)                                                                         \
    do {                                                                                     \
        if (!(x)) {                                                                          \
            __builtin_trap();                                                                \
        }                                                                                    \
    } while (0)
#else
#define SL_ASSERT(x)                                                                         \
    do {                                                                                     \
        if (!(x)) {                                                                          \
            for (;;) {                                                                       \
            }                                                                                \
        }                                                                                    \
    } while (0)
#endif
#endif

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_SL_ERR_H
