// SPDX-License-Identifier: MIT
// Links the installed core and a board's tables, and runs the estimator on one return:
// what an integrator's first program does with the SDK.
#include <stdio.h>
#include <string.h>

#include "shadowlean/sl_board.h"
#include "shadowlean/sl_incline.h"
#include "shadowlean/sl_version.h"
#include "sl_board_paper_sim.h"

int main(void)
{
    const sl_board_t *b = sl_board_find("paper-sim");
    if (b == NULL || b != &sl_board_paper_sim) {
        fprintf(stderr, "board paper-sim not found in the installed core\n");
        return 1;
    }
    // A pole at 2.5 m whose return spans 2.5 .. 3.0 m on azimuth 0.
    const sl_incline_result_t r = sl_incline_estimate(2500000U, 3000000U, &b->geom[0], 20000U, 10U);
    printf("shadowlean %s: board %s, %u azimuths, alpha %d cdeg (flag %u)\n", SL_VERSION_STRING,
           b->name, (unsigned)b->azimuths, (int)r.alpha_cdeg, (unsigned)r.flag);
    return r.flag == SL_INCLINE_VALID ? 0 : 1;
}
