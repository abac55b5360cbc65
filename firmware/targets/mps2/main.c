// The example firmware's main (QEMU MPS2 boards): calibrates SysTick against a loop of known
// instruction count, runs the core pipeline over the capture linked into flash (fw_app.c),
// and reports over semihosting:
//   the frames and rotations (compared with the host's by ctest, label thumb),
//   "thumb: <cpu> <N> instructions per azimuth", the stack high-water mark, RAM of the pipeline.
// Exit status 0 when the run completed.
#include <stddef.h>
#include <stdint.h>

#include "fw_app.h"
#include "mps2.h"
#include "shadowlean/sl_pipeline.h"

#ifndef SL_FW_CPU
#define SL_FW_CPU "cortex-m"
#endif
#ifndef SL_FW_BOARD
#define SL_FW_BOARD NULL
#endif
#define CAL_LOOPS 1000000U // 2 instructions each (subs + bne)

extern const uint8_t fw_capture[], fw_capture_end[];
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
    const size_t len = (size_t)(fw_capture_end - fw_capture);
    line2("capture ", len, " bytes in flash\n");
    const sl_err_t e = fw_app_run(&pf, SL_FW_BOARD, fw_capture, len, 1460U, &res);
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
