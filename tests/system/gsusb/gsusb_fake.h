// SPDX-License-Identifier: MIT
/// @file gsusb_fake.h
/// @brief In-process fake candleLight behind the gs_usb transport seam (unit tests only).
///
/// Behaves like candleLight_fw as seen from the host: answers DEVICE_CONFIG, BT_CONST and
/// GET_STATE, takes HOST_FORMAT, BITTIMING and MODE, stalls every other request; echoes
/// each bulk OUT frame back on bulk IN (24 bytes with a timestamp when MODE started with
/// HW_TIMESTAMP), optionally injects an RX reply (id + 1) per frame. Misbehaviour knobs:
/// refused/timed-out requests, short answers, halted endpoints, lost echoes, a busy OUT
/// endpoint, vanishing after N frames. Everything the host sent is recorded.
/// Plain C, endian-clean (runs under qemu-user on aarch64 and s390x).
#ifndef SHADOWLEAN_TESTS_GSUSB_FAKE_H
#define SHADOWLEAN_TESTS_GSUSB_FAKE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gsusb/gsusb_proto.h"

#define FAKE_MAX_REQS 64U
#define FAKE_MAX_FRAMES 256U
#define FAKE_INQ 128U

/// One control request as the host sent it.
typedef struct fake_req {
    uint8_t rt;
    uint8_t breq;
    uint16_t wvalue;
    uint16_t windex;
    uint16_t len;
    uint8_t data[64]; ///< OUT payload (first 64 bytes)
} fake_req_t;

typedef struct gsusb_fake {
    // --- device properties (gsusb_fake_init: a 48 MHz STM32F072 candleLight)
    slp_gsusb_device_config_t dev_cfg;
    slp_gsusb_bt_const_t bt_const;
    slp_gsusb_can_state_t can_state;

    // --- misbehaviour knobs
    uint32_t refuse_mask;       ///< bit n set: request n is stalled
    uint32_t timeout_mask;      ///< bit n set: request n times out
    uint32_t short_mask;        ///< bit n set: IN request n answers 2 bytes too few
    bool gone;                  ///< every call: NO_DEVICE
    int vanish_after_frames;    ///< once this many frames were accepted: gone (-1: never)
    int echo_limit;             ///< echo only the first k frames (-1: all)
    bool inject_reply;          ///< per frame an RX frame id + 1 with the same data
    int stall_out_at;           ///< bulk OUT of frame index k is stalled once (-1: never)
    int stall_in_after;         ///< after accepting frame k the IN endpoint halts (-1: never)
    bool out_busy;              ///< bulk OUT times out (device not accepting)
    int out_error_count;        ///< the next k bulk OUTs fail with ERROR
    int in_error_count;         ///< the next k bulk INs fail with ERROR
    bool clear_halt_fails;

    // --- state
    bool out_halted;
    bool in_halted;
    bool started;
    uint32_t mode_flags;
    slp_gsusb_bittiming_t bt;
    bool bt_set;
    uint32_t clock_us;          ///< device timestamp counter (advances 100 per frame)

    // --- records
    fake_req_t reqs[FAKE_MAX_REQS];
    size_t n_reqs;
    slp_gsusb_host_frame_t frames[FAKE_MAX_FRAMES]; ///< accepted bulk OUT frames
    size_t frame_len[FAKE_MAX_FRAMES];
    size_t n_frames;
    size_t n_echoed;
    uint32_t clear_halts_in;
    uint32_t clear_halts_out;
    uint32_t bulk_out_calls;

    // --- bulk IN queue (packets waiting for the host)
    uint8_t inq[FAKE_INQ][32];
    size_t inq_len[FAKE_INQ];
    size_t inq_head;
    size_t inq_count;
} gsusb_fake_t;

/// candleLight defaults: 1 channel, sw 2 / hw 1, 48 MHz, bxCAN limits (tseg1 1..16,
/// tseg2 1..8, sjw 4, brp 1..1024 step 1), features LISTEN_ONLY|LOOP_BACK|ONE_SHOT|GET_STATE.
void gsusb_fake_init(gsusb_fake_t *f);

/// The transport that talks to `f`.
slp_gsusb_transport_t gsusb_fake_transport(gsusb_fake_t *f);

/// Queue a raw IN packet (at most 32 bytes).
void gsusb_fake_push_in(gsusb_fake_t *f, const uint8_t *pkt, size_t len);

/// Queue an RX frame from the bus (echo_id 0xFFFFFFFF) in the device's current format.
void gsusb_fake_push_rx(gsusb_fake_t *f, uint32_t can_id, uint8_t dlc, const uint8_t *data,
                        uint8_t flags, uint8_t channel);

/// Index of the first recorded request `breq` at or after `from`, or -1.
int gsusb_fake_find_req(const gsusb_fake_t *f, uint8_t breq, size_t from);

#endif // SHADOWLEAN_TESTS_GSUSB_FAKE_H
