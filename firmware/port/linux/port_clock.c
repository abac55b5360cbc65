// SPDX-License-Identifier: MIT
// port_clock.c: the Linux port's clock (CLOCK_MONOTONIC, microseconds).
#include "port_clock.h"

#include <time.h>

uint64_t slp_now_us(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000U + (uint64_t)ts.tv_nsec / 1000U;
}
