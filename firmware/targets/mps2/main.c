// SPDX-License-Identifier: MIT
// The example firmware's main (QEMU MPS2 boards): calibrates SysTick against a loop of known
// instruction count, runs the core pipeline over the capture linked into flash (fw_app.c)
// or, when QEMU placed one in the board's 16 MB PSRAM, over that one (a capture too
// large for flash, e.g. the Oxford scans: see PSRAM_* below), and reports over semihosting:
//   the frames and rotations (compared with the host's by ctest, label thumb),
//   "thumb: <cpu> <N> instructions per azimuth", the stack high-water mark, RAM of the pipeline.
// Exit status 0 when the run completed.
#include <stddef.h>
#include <stdint.h>

#include "fw_app.h"
#include "mps2.h"
#include "shadowlean/sl_board.h"
#include "shadowlean/sl_pipeline.h"

#ifndef SL_FW_CPU
#define SL_FW_CPU "cortex-m"
#endif
#ifndef SL_FW_BOARD
#define SL_FW_BOARD NULL
#endif
#define CAL_LOOPS 1000000U // 2 instructions each (subs + bne)

extern const uint8_t fw_capture[], fw_capture_end[];

// A capture in PSRAM (MPS2: 16 MB at 0x21000000), put there by QEMU's generic loader:
//   -device loader,addr=0x21000000,data=0x50434c53,data-len=4     magic "SLCP"
//   -device loader,addr=0x21000004,data=<bytes>,data-len=4        length
//   -device loader,addr=0x21000008,data=<i>,data-len=4            board: sl_board_at(i)
//   -device loader,addr=0x2100000c,data=<n>,data-len=4            feed chunk (0: 1460)
//   -device loader,file=<capture>,addr=0x21000010,force-raw=on    the bytes
#define PSRAM_BASE 0x21000000U
#define PSRAM_MAGIC 0x50434c53U
#define PSRAM_DATA (PSRAM_BASE + 16U)
#define PSRAM_MAX (0x01000000U - 16U)
extern uint32_t _sstack, _estack;

void mps2_calib_loop(uint32_t n); // calib.S: 2 n instructions

static uint32_t calibrate(void)
{
    const uint32_t t0 = mps2_ticks();
    mps2_calib_loop(CAL_LOOPS);
    return (mps2_ticks() - t0) & 0x00FFFFFFU;
}

static void line2(const char *a, uint64_t v, const char *b)
{
    char num[21];
    mps2_write(a);
    mps2_write(fw_u64(num, v));
    mps2_write(b);
}

static uint32_t stack_high_water(void)
{
    const uint32_t *p = &_sstack;
    while (p < &_estack && *p == MPS2_STACK_PAINT) {
        p++;
    }
    return (uint32_t)((uintptr_t)&_estack - (uintptr_t)p);
}

int main(void)
{
    mps2_systick_start();
    const uint32_t cal = calibrate();
    const fw_platform_t pf = {mps2_write, mps2_ticks, 0x00FFFFFFU};
    fw_result_t res;
    const uint8_t *cap = fw_capture;
    size_t len = (size_t)(fw_capture_end - fw_capture);
    const char *board = SL_FW_BOARD;
    size_t chunk = 1460U; // a TCP segment
    const volatile uint32_t *hdr = (const volatile uint32_t *)PSRAM_BASE;
    if (hdr[0] == PSRAM_MAGIC && hdr[1] <= PSRAM_MAX) { // QEMU's loader put one there
        const sl_board_t *b = sl_board_at(hdr[2]);
        if (b == NULL) {
            mps2_write("PSRAM capture: no such board index\n");
            return 1;
        }
        cap = (const uint8_t *)PSRAM_DATA;
        len = hdr[1];
        board = b->name;
        if (hdr[3] != 0U) {
            chunk = hdr[3];
        }
        line2("capture ", len, " bytes in PSRAM, board ");
        mps2_write(board);
        mps2_write("\n");
    } else {
        line2("capture ", len, " bytes in flash\n");
    }
    line2("feed chunks of ", chunk, " bytes\n");
    const sl_err_t e = fw_app_run(&pf, board, cap, len, chunk, &res);
    if (e != SL_OK) {
        mps2_write("fw_app_run failed: ");
        mps2_write(sl_err_str(e));
        mps2_write("\n");
        return 1;
    }
    // instructions = ticks x (2 CAL_LOOPS / cal), rounded.
    const uint64_t instr = cal != 0U ? (res.ticks * 2U * CAL_LOOPS + cal / 2U) / cal : 0U;
    line2("calibration ", cal, " ticks for 2000000 instructions\n");
    line2("azimuths ", res.azimuths, "\n");
    line2("rotations ", res.rotations, "\n");
    line2("targets ", res.targets, "\n");
    line2("frames ", res.frames, "\n");
    line2("frames_lost ", res.frames_lost, "\n");
    line2("instructions ", instr, " in sl_pipeline_feed/finish\n");
    mps2_write("thumb: " SL_FW_CPU " ");
    line2("", res.azimuths != 0U ? (instr + res.azimuths / 2U) / res.azimuths : 0U,
          " instructions per azimuth\n");
    line2("stack high-water ", stack_high_water(), " bytes (whole image, from reset)\n");
    line2("sizeof(sl_pipeline_t) ", sizeof(sl_pipeline_t), " bytes\n");
    mps2_write("done\n");
    return res.frames_lost == 0U ? 0 : 1;
}
