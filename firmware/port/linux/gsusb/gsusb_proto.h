// SPDX-License-Identifier: MIT
/// @file gsusb_proto.h
/// @brief gs_usb (candleLight) protocol layer and driver logic, behind a transport seam.
///
/// Plain C11 with no libusb and no OS calls, so the unit tests can run it against an
/// in-process fake device on every test target (x86-64, aarch64, big-endian s390x).
/// The libusb-1.0 transport lives in gsusb_usb.h; the daemon-facing CAN sink in
/// gsusb_sink.h. Facts and sources: docs/CAN_AND_USB.md s.1.
///
/// Three parts:
/// 1. **Codec** (pure functions): vendor request payloads (HOST_FORMAT, DEVICE_CONFIG,
///    BT_CONST, BITTIMING, MODE, GET_STATE), the `gs_host_frame` bulk frame (20 bytes, 24
///    with the hardware timestamp, 21 with the LPC546xx quirk byte). Every multi-byte field
///    is little-endian on the wire and is assembled byte by byte (endian-clean).
/// 2. **Bit timing** from the device clock and BT_CONST limits: the same search as Linux
///    `can_calc_bittiming()` (kernel 6.1), so this driver and the kernel's gs_usb program
///    identical registers (500 kbit/s at 48 MHz: brp 6, prop 6, ph1 7, ph2 2, sjw 1, 87.5 %).
/// 3. **Driver** (`slp_gsusb_t`): the start-up sequence, transmit with echo ids (at most N
///    frames in flight, default 10 as the kernel's GS_MAX_TX_URBS), echo confirmation and
///    timeouts, the receive path (RX frames, error frames, overflow flag), stall recovery
///    (clear_halt + one retry), device-vanished handling, clean stop. All I/O goes through
///    `slp_gsusb_transport_t` (a const vtable + context).
///
/// ## Errors
/// API functions return `sl_err_t`. Problems of the device or the bus are counted in
/// `stats`; the first failure of a start-up is also described in `last_error` (text).
///
/// ## Threading and cost
/// Not thread-safe: one thread drives one `slp_gsusb_t` (the transport's blocking calls are
/// bounded by the timeouts below). No allocation; `slp_gsusb_t` is about 1.5 KB.
#ifndef SHADOWLEAN_PORT_GSUSB_PROTO_H
#define SHADOWLEAN_PORT_GSUSB_PROTO_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "shadowlean/sl_can.h"
#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

// =======================================================================================
// USB identity (CAN_AND_USB.md s.1.1)

/// One known gs_usb VID:PID.
typedef struct slp_gsusb_usb_id {
    uint16_t vid;
    uint16_t pid;
    const char *name; ///< human-readable device family
} slp_gsusb_usb_id_t;

/// The known gs_usb ids (1d50:606f first: every candleLight_fw build). Static table.
/// @param[out] n number of entries. @return the table (never NULL).
const slp_gsusb_usb_id_t *slp_gsusb_known_ids(size_t *n);

/// True when vid:pid is in the known-id table. O(entries).
bool slp_gsusb_is_known_id(uint16_t vid, uint16_t pid);

#define SLP_GSUSB_INTERFACE 0U          ///< the gs_usb interface (the kernel binds only this one)
#define SLP_GSUSB_EP_IN_DEFAULT 0x81U   ///< candleLight bulk IN (fallback when not in the descriptor)
#define SLP_GSUSB_EP_OUT_DEFAULT 0x02U  ///< candleLight bulk OUT

// =======================================================================================
// Vendor control requests (CAN_AND_USB.md s.1.2)

#define SLP_GSUSB_RT_OUT 0x41U ///< bmRequestType host->device: vendor, interface
#define SLP_GSUSB_RT_IN 0xC1U  ///< bmRequestType device->host: vendor, interface

/// bRequest values.
typedef enum slp_gsusb_breq {
    SLP_GSUSB_BREQ_HOST_FORMAT = 0,
    SLP_GSUSB_BREQ_BITTIMING = 1,
    SLP_GSUSB_BREQ_MODE = 2,
    SLP_GSUSB_BREQ_BERR = 3,
    SLP_GSUSB_BREQ_BT_CONST = 4,
    SLP_GSUSB_BREQ_DEVICE_CONFIG = 5,
    SLP_GSUSB_BREQ_TIMESTAMP = 6,
    SLP_GSUSB_BREQ_IDENTIFY = 7,
    SLP_GSUSB_BREQ_DATA_BITTIMING = 10,
    SLP_GSUSB_BREQ_BT_CONST_EXT = 11,
    SLP_GSUSB_BREQ_SET_TERMINATION = 12,
    SLP_GSUSB_BREQ_GET_TERMINATION = 13,
    SLP_GSUSB_BREQ_GET_STATE = 14,
} slp_gsusb_breq_t;

/// Short upper-case name of a request ("BITTIMING"), "REQ?" when unknown. Static string.
const char *slp_gsusb_breq_name(uint8_t breq);

// Payload sizes (bytes).
#define SLP_GSUSB_HOST_FORMAT_BYTES 4U
#define SLP_GSUSB_BITTIMING_BYTES 20U
#define SLP_GSUSB_MODE_BYTES 8U
#define SLP_GSUSB_BT_CONST_BYTES 40U
#define SLP_GSUSB_DEVICE_CONFIG_BYTES 12U
#define SLP_GSUSB_STATE_BYTES 12U

#define SLP_GSUSB_HOST_FORMAT_WORD 0x0000BEEFUL ///< HOST_FORMAT payload (sent LE: ef be 00 00)

// Feature bits (BT_CONST.feature); the same positions switch a feature on in MODE.flags.
#define SLP_GSUSB_FEAT_LISTEN_ONLY (1UL << 0)
#define SLP_GSUSB_FEAT_LOOP_BACK (1UL << 1)
#define SLP_GSUSB_FEAT_TRIPLE_SAMPLE (1UL << 2)
#define SLP_GSUSB_FEAT_ONE_SHOT (1UL << 3)
#define SLP_GSUSB_FEAT_HW_TIMESTAMP (1UL << 4)
#define SLP_GSUSB_FEAT_IDENTIFY (1UL << 5)
#define SLP_GSUSB_FEAT_USER_ID (1UL << 6)
#define SLP_GSUSB_FEAT_PAD_PKTS (1UL << 7)
#define SLP_GSUSB_FEAT_FD (1UL << 8)
#define SLP_GSUSB_FEAT_QUIRK_LPC546XX (1UL << 9)
#define SLP_GSUSB_FEAT_BT_CONST_EXT (1UL << 10)
#define SLP_GSUSB_FEAT_TERMINATION (1UL << 11)
#define SLP_GSUSB_FEAT_BERR_REPORTING (1UL << 12)
#define SLP_GSUSB_FEAT_GET_STATE (1UL << 13)

/// MODE.flags a caller may ask for through `slp_gsusb_cfg_t.mode_flags` (bench features).
#define SLP_GSUSB_MODE_FLAGS_ALLOWED                                                          \
    (SLP_GSUSB_FEAT_LISTEN_ONLY | SLP_GSUSB_FEAT_LOOP_BACK | SLP_GSUSB_FEAT_TRIPLE_SAMPLE |    \
     SLP_GSUSB_FEAT_ONE_SHOT)

#define SLP_GSUSB_MODE_RESET 0UL ///< MODE.mode: stop the channel
#define SLP_GSUSB_MODE_START 1UL ///< MODE.mode: start the channel

/// DEVICE_CONFIG answer.
typedef struct slp_gsusb_device_config {
    uint8_t icount;       ///< number of channels - 1
    uint32_t sw_version;  ///< candleLight: 2
    uint32_t hw_version;  ///< candleLight: 1
} slp_gsusb_device_config_t;

/// BT_CONST answer: feature bitmap, CAN clock and bit-timing limits (in time quanta).
typedef struct slp_gsusb_bt_const {
    uint32_t feature;  ///< SLP_GSUSB_FEAT_* bits the device offers
    uint32_t fclk_hz;  ///< CAN controller clock
    uint32_t tseg1_min, tseg1_max; ///< prop_seg + phase_seg1
    uint32_t tseg2_min, tseg2_max; ///< phase_seg2
    uint32_t sjw_max;
    uint32_t brp_min, brp_max, brp_inc;
} slp_gsusb_bt_const_t;

/// BITTIMING payload (time quanta; brp = clock prescaler). Bit = (1 + prop + ph1 + ph2) tq.
typedef struct slp_gsusb_bittiming {
    uint32_t prop_seg;
    uint32_t phase_seg1;
    uint32_t phase_seg2;
    uint32_t sjw;
    uint32_t brp;
} slp_gsusb_bittiming_t;

/// GET_STATE answer.
typedef struct slp_gsusb_can_state {
    uint32_t state; ///< 0 active, 1 warning, 2 passive, 3 bus-off, 4 stopped, 5 sleeping
    uint32_t rxerr; ///< receive error counter
    uint32_t txerr; ///< transmit error counter
} slp_gsusb_can_state_t;

/// HOST_FORMAT payload (4 bytes: ef be 00 00). O(1).
void slp_gsusb_encode_host_format(uint8_t out[SLP_GSUSB_HOST_FORMAT_BYTES]);

/// BITTIMING payload (5 LE u32: prop_seg, phase_seg1, phase_seg2, sjw, brp). O(1).
void slp_gsusb_encode_bittiming(const slp_gsusb_bittiming_t *bt, uint8_t out[SLP_GSUSB_BITTIMING_BYTES]);

/// MODE payload (LE u32 mode, LE u32 flags). O(1).
void slp_gsusb_encode_mode(uint32_t mode, uint32_t flags, uint8_t out[SLP_GSUSB_MODE_BYTES]);

/// Decode a DEVICE_CONFIG answer of `len` bytes.
/// @return SL_OK, SL_ERR_MALFORMED (len < 12: nothing written), SL_ERR_ARG (NULL).
sl_err_t slp_gsusb_decode_device_config(const uint8_t *buf, size_t len, slp_gsusb_device_config_t *out);

/// Decode a BT_CONST answer (40 bytes). Does not judge the limits (see
/// slp_gsusb_bt_const_check). @return SL_OK, SL_ERR_MALFORMED (short), SL_ERR_ARG.
sl_err_t slp_gsusb_decode_bt_const(const uint8_t *buf, size_t len, slp_gsusb_bt_const_t *out);

/// Decode a BITTIMING payload (the fake device and tests use it). Same returns.
sl_err_t slp_gsusb_decode_bittiming(const uint8_t *buf, size_t len, slp_gsusb_bittiming_t *out);

/// Decode a GET_STATE answer (12 bytes). Same returns.
sl_err_t slp_gsusb_decode_state(const uint8_t *buf, size_t len, slp_gsusb_can_state_t *out);

/// Plausibility of BT_CONST limits: clock > 0, min <= max for tseg1/tseg2/brp, tseg2_max
/// and brp_max >= 1, brp_inc >= 1, tseg1_max and tseg2_max <= SLP_GSUSB_TSEG_LIMIT (no
/// controller goes near it; it bounds the search). @return SL_OK or SL_ERR_MALFORMED.
sl_err_t slp_gsusb_bt_const_check(const slp_gsusb_bt_const_t *c);
#define SLP_GSUSB_TSEG_LIMIT 1024U

// =======================================================================================
// Bit timing

/// Largest accepted bit-rate error: 0.5 % (5000 ppm). Linux accepts 5 %; a CAN node that far
/// off a bus's rate would not communicate reliably, so this driver refuses it up front.
#define SLP_GSUSB_MAX_RATE_ERROR_PPM 5000U
/// Classic CAN (ISO 11898-1) tops out at 1 Mbit/s.
#define SLP_GSUSB_MAX_BITRATE 1000000UL

/// Result of a bit-timing search (filled also when it fails, with the best candidate).
typedef struct slp_gsusb_bt_result {
    slp_gsusb_bittiming_t bt;         ///< the register values (valid when SL_OK)
    uint32_t bitrate;                ///< rate actually produced: fclk / (brp x tq per bit)
    uint32_t error_ppm;              ///< |requested - produced| / requested, ppm
    uint16_t sample_point_permille;  ///< produced sample point, 1000 x (1+tseg1)/(1+tseg1+tseg2)
    uint16_t sample_point_nominal;   ///< the sample point aimed at
    uint16_t tq_per_bit;             ///< 1 + tseg1 + tseg2 (0 when no candidate fitted)
} slp_gsusb_bt_result_t;

/// Default sample point for a bit rate, as Linux (and CiA 301 for <= 500 kbit/s):
/// 875 permille up to 500 kbit/s, 800 up to 800 kbit/s, 750 above.
uint16_t slp_gsusb_default_sample_point(uint32_t bitrate);

/// Compute BITTIMING for `bitrate` bit/s from the device clock and limits in `c`, aiming at
/// `sample_point_permille` (0 = slp_gsusb_default_sample_point()). The search is Linux's
/// can_calc_bittiming() (6.1): total time quanta from the largest down; the smallest rate
/// error wins, then the smallest sample-point error not above the nominal one; prop_seg =
/// tseg1 / 2, phase_seg1 = tseg1 - prop_seg; sjw = 1.
/// @return SL_OK; SL_ERR_ARG (NULL, bitrate 0, sample point >= 1000);
///         SL_ERR_RANGE (bitrate above 1 Mbit/s, no prescaler in [brp_min, brp_max] fits,
///         or the best error exceeds SLP_GSUSB_MAX_RATE_ERROR_PPM: `out` holds the best try);
///         SL_ERR_MALFORMED (implausible limits, see slp_gsusb_bt_const_check).
/// Cost: O(tseg1_max + tseg2_max) iterations, a few divisions each.
sl_err_t slp_gsusb_bittiming_calc(const slp_gsusb_bt_const_t *c, uint32_t bitrate,
                                 uint16_t sample_point_permille, slp_gsusb_bt_result_t *out);

/// Bit rate produced by `bt` at clock `fclk_hz` (0 when brp or the segments are 0). O(1).
uint32_t slp_gsusb_bittiming_rate(const slp_gsusb_bittiming_t *bt, uint32_t fclk_hz);

// =======================================================================================
// Bulk frame: gs_host_frame (CAN_AND_USB.md s.1.3)

#define SLP_GSUSB_ECHO_ID_RX 0xFFFFFFFFUL ///< echo_id of frames received from the bus
#define SLP_GSUSB_CAN_EFF_FLAG 0x80000000UL ///< can_id bit 31: 29-bit id
#define SLP_GSUSB_CAN_RTR_FLAG 0x40000000UL ///< can_id bit 30: remote request
#define SLP_GSUSB_CAN_ERR_FLAG 0x20000000UL ///< can_id bit 29: error frame
#define SLP_GSUSB_CAN_ERR_MASK 0x1FFFFFFFUL ///< error class bits of an error frame

#define SLP_GSUSB_FRAME_FLAG_OVERFLOW 0x01U ///< the device's RX FIFO overflowed
#define SLP_GSUSB_FRAME_FLAG_FD 0x02U
#define SLP_GSUSB_FRAME_FLAG_BRS 0x04U
#define SLP_GSUSB_FRAME_FLAG_ESI 0x08U

#define SLP_GSUSB_FRAME_HEADER_BYTES 12U  ///< echo_id, can_id, dlc, channel, flags, reserved
#define SLP_GSUSB_FRAME_BYTES 20U         ///< classic frame
#define SLP_GSUSB_FRAME_TS_BYTES 24U      ///< classic + LE u32 timestamp_us
#define SLP_GSUSB_FRAME_QUIRK_BYTES 21U   ///< classic + LPC546xx padding byte (TX only)
#define SLP_GSUSB_FRAME_MAX_BYTES 24U

/// One classic gs_host_frame, fields as on the wire (can_id with the SocketCAN flag bits).
typedef struct slp_gsusb_host_frame {
    uint32_t echo_id;
    uint32_t can_id;
    uint8_t can_dlc;
    uint8_t channel;
    uint8_t flags;    ///< SLP_GSUSB_FRAME_FLAG_*
    uint8_t reserved;
    uint8_t data[8];
    uint32_t timestamp_us; ///< only on the wire in the 24-byte format
} slp_gsusb_host_frame_t;

/// Frame format options.
#define SLP_GSUSB_FMT_TIMESTAMP 0x01U ///< 24 bytes with timestamp_us (RX, HW_TIMESTAMP on)
#define SLP_GSUSB_FMT_QUIRK 0x02U     ///< 21 bytes (TX to an LPC546xx-quirk device)

/// Size of a frame in format `fmt` (20, 21 or 24). O(1).
size_t slp_gsusb_frame_size(unsigned fmt);

/// Encode `hf` into `buf`. @return the size written (20/21/24), SL_ERR_FULL when `cap` is
/// too small, SL_ERR_ARG (NULL, both format bits). O(1).
sl_ssize_t slp_gsusb_frame_encode(const slp_gsusb_host_frame_t *hf, unsigned fmt, uint8_t *buf,
                                 size_t cap);

/// Decode `len` received bytes. With SLP_GSUSB_FMT_TIMESTAMP at least 24 bytes are needed,
/// otherwise 20; extra bytes (padding to the packet size) are ignored.
/// @return SL_OK, SL_ERR_MALFORMED (too short: nothing written), SL_ERR_ARG (NULL). O(1).
sl_err_t slp_gsusb_frame_decode(const uint8_t *buf, size_t len, unsigned fmt,
                               slp_gsusb_host_frame_t *out);

/// shadowlean frame -> wire frame (echo_id, channel set; flags/reserved 0; RTR sends no data).
/// @return SL_OK; SL_ERR_ARG (NULL, dlc > 8, id wider than 11/29 bits, ERR flag set).
sl_err_t slp_gsusb_frame_from_can(const sl_can_frame_t *f, uint32_t echo_id, uint8_t channel,
                                 slp_gsusb_host_frame_t *out);

/// Wire frame -> shadowlean frame. Error frames keep their class bits in `id` with
/// SL_CAN_FLAG_ERR. @return SL_OK; SL_ERR_MALFORMED (FD frame, dlc > 8, ERR together with
/// RTR); SL_ERR_ARG (NULL).
sl_err_t slp_gsusb_frame_to_can(const slp_gsusb_host_frame_t *hf, sl_can_frame_t *out);

// Error frame classes (linux/can/error.h) and controller status bits (data[1]).
#define SLP_GSUSB_ERR_TX_TIMEOUT 0x001U
#define SLP_GSUSB_ERR_LOSTARB 0x002U
#define SLP_GSUSB_ERR_CRTL 0x004U
#define SLP_GSUSB_ERR_PROT 0x008U
#define SLP_GSUSB_ERR_TRX 0x010U
#define SLP_GSUSB_ERR_ACK 0x020U
#define SLP_GSUSB_ERR_BUSOFF 0x040U
#define SLP_GSUSB_ERR_BUSERROR 0x080U
#define SLP_GSUSB_ERR_RESTARTED 0x100U
#define SLP_GSUSB_ERR_CRTL_RX_OVERFLOW 0x01U
#define SLP_GSUSB_ERR_CRTL_TX_OVERFLOW 0x02U
#define SLP_GSUSB_ERR_CRTL_RX_WARNING 0x04U
#define SLP_GSUSB_ERR_CRTL_TX_WARNING 0x08U
#define SLP_GSUSB_ERR_CRTL_RX_PASSIVE 0x10U
#define SLP_GSUSB_ERR_CRTL_TX_PASSIVE 0x20U
#define SLP_GSUSB_ERR_CRTL_ACTIVE 0x40U

// =======================================================================================
// Echo ids: the transmit window

/// Compile-time upper bound of the window (echo ids 0 .. capacity-1).
#define SLP_GSUSB_MAX_IN_FLIGHT 32U
/// Default window: the kernel's GS_MAX_TX_URBS.
#define SLP_GSUSB_DEFAULT_IN_FLIGHT 10U

/// One transmitted frame waiting for its echo.
typedef struct slp_gsusb_echo_slot {
    bool in_use;
    uint32_t tag;          ///< caller's cookie (e.g. a sequence number)
    uint64_t sent_us;      ///< time the bulk OUT completed
    sl_can_frame_t frame;  ///< what was sent (for the confirmation callback and the check)
} slp_gsusb_echo_slot_t;

/// Echo-id table. Echo ids are slot indexes 0..capacity-1 (what the kernel sends, so every
/// firmware tested against Linux accepts them); a free id is taken round-robin, so an id
/// freed by a timeout is reused as late as possible (a very late echo then most likely
/// finds its slot empty and is counted as unknown instead of confirming the wrong frame).
/// Fields read-only to the application.
typedef struct slp_gsusb_echo {
    uint8_t capacity;
    uint8_t in_flight;
    uint8_t next;          ///< where the round-robin search starts
    slp_gsusb_echo_slot_t slot[SLP_GSUSB_MAX_IN_FLIGHT];
    struct {
        uint32_t allocated;     ///< ids handed out
        uint32_t full;          ///< alloc refused: window full
        uint32_t confirmed;     ///< echoes matched to a frame in flight
        uint32_t unknown;       ///< echoes for an id not in flight (late, or bogus)
        uint32_t timeouts;      ///< frames whose echo did not come in time
        uint32_t dropped;       ///< frames given up without an echo (device gone, stop)
        uint8_t max_in_flight;  ///< high-water mark
    } stats;
} slp_gsusb_echo_t;

/// Why a frame left the window.
typedef enum slp_gsusb_tx_result {
    SLP_GSUSB_TX_CONFIRMED = 0, ///< the device echoed it: it went out on the bus
    SLP_GSUSB_TX_TIMEOUT = 1,   ///< no echo within the timeout: unconfirmed (maybe not sent)
    SLP_GSUSB_TX_DROPPED = 2,   ///< given up: device vanished or the channel was stopped
} slp_gsusb_tx_result_t;

/// Called for every frame leaving the window. `slot` is valid during the call only.
typedef void (*slp_gsusb_echo_done_fn)(void *ctx, uint32_t echo_id, const slp_gsusb_echo_slot_t *slot,
                                      slp_gsusb_tx_result_t result);

/// Initialise with `capacity` ids (0 = SLP_GSUSB_DEFAULT_IN_FLIGHT).
/// @return SL_OK or SL_ERR_ARG (capacity > SLP_GSUSB_MAX_IN_FLIGHT). O(capacity).
sl_err_t slp_gsusb_echo_init(slp_gsusb_echo_t *e, uint8_t capacity);

/// Take a free echo id for `frame` sent at `now_us`. @return the id (>= 0) or SL_ERR_FULL
/// (counted in stats.full). O(capacity).
sl_ssize_t slp_gsusb_echo_alloc(slp_gsusb_echo_t *e, const sl_can_frame_t *frame, uint32_t tag,
                               uint64_t now_us);

/// Give an id back without a result (the bulk OUT failed, nothing was sent).
/// @return SL_OK or SL_ERR_ARG (not in flight). O(1).
sl_err_t slp_gsusb_echo_release(slp_gsusb_echo_t *e, uint32_t echo_id);

/// The slot of `echo_id` when it is in flight, else NULL (never counted). O(1).
const slp_gsusb_echo_slot_t *slp_gsusb_echo_peek(const slp_gsusb_echo_t *e, uint32_t echo_id);

/// An echo arrived: free its id and copy the slot to `*done` (may be NULL).
/// @return SL_OK, or SL_ERR_MALFORMED for an id not in flight (counted in stats.unknown). O(1).
sl_err_t slp_gsusb_echo_confirm(slp_gsusb_echo_t *e, uint32_t echo_id, slp_gsusb_echo_slot_t *done);

/// Free every id older than `timeout_us` at `now_us` (result SLP_GSUSB_TX_TIMEOUT, counted);
/// `cb` (may be NULL) sees each. @return how many expired. O(capacity).
size_t slp_gsusb_echo_expire(slp_gsusb_echo_t *e, uint64_t now_us, uint64_t timeout_us,
                            slp_gsusb_echo_done_fn cb, void *ctx);

/// Free every id (result SLP_GSUSB_TX_DROPPED, counted). @return how many. O(capacity).
size_t slp_gsusb_echo_drop_all(slp_gsusb_echo_t *e, slp_gsusb_echo_done_fn cb, void *ctx);

/// Earliest `sent_us + timeout_us` over the ids in flight; UINT64_MAX when none. O(capacity).
uint64_t slp_gsusb_echo_deadline(const slp_gsusb_echo_t *e, uint64_t timeout_us);

// =======================================================================================
// Transport seam

/// Outcome of one transfer.
typedef enum slp_gsusb_io {
    SLP_GSUSB_IO_OK = 0,        ///< done; `*transferred` bytes
    SLP_GSUSB_IO_TIMEOUT = 1,   ///< nothing (or only `*transferred` bytes) within the timeout
    SLP_GSUSB_IO_STALL = 2,     ///< the device stalled (control: refused the request)
    SLP_GSUSB_IO_NO_DEVICE = 3, ///< the device is gone (unplugged, reset, UDC unbound)
    SLP_GSUSB_IO_OVERFLOW = 4,  ///< the device sent more than the buffer holds
    SLP_GSUSB_IO_ERROR = 5,     ///< any other failure
} slp_gsusb_io_t;

/// Name of an io code ("STALL"). Static string.
const char *slp_gsusb_io_name(slp_gsusb_io_t io);

/// The transport operations. Every call returns within its timeout (0 = do not wait: report
/// only what has already completed; meaningful for bulk_in). `transferred` is never NULL.
typedef struct slp_gsusb_transport_ops {
    /// Vendor control request host->device: bmRequestType `rt` (0x41), `len` bytes of `data`.
    slp_gsusb_io_t (*control_out)(void *ctx, uint8_t rt, uint8_t breq, uint16_t wvalue,
                                 uint16_t windex, const uint8_t *data, uint16_t len,
                                 uint32_t timeout_ms, size_t *transferred);
    /// Vendor control request device->host (0xC1): up to `len` bytes into `data`.
    slp_gsusb_io_t (*control_in)(void *ctx, uint8_t rt, uint8_t breq, uint16_t wvalue,
                                uint16_t windex, uint8_t *data, uint16_t len, uint32_t timeout_ms,
                                size_t *transferred);
    /// One bulk OUT transfer (one gs_host_frame).
    slp_gsusb_io_t (*bulk_out)(void *ctx, const uint8_t *data, size_t len, uint32_t timeout_ms,
                              size_t *transferred);
    /// The next bulk IN packet (one gs_host_frame, maybe padded), waiting at most timeout_ms.
    slp_gsusb_io_t (*bulk_in)(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms,
                             size_t *transferred);
    /// Clear a halted bulk endpoint (`in`: the IN endpoint) and resume it. May be NULL.
    slp_gsusb_io_t (*clear_halt)(void *ctx, bool in);
    /// True when an earlier (asynchronous) bulk OUT ended in a stall that is not cleared
    /// yet; slp_gsusb_poll() then clears it. May be NULL (synchronous transports report the
    /// stall from bulk_out itself).
    bool (*out_stalled)(void *ctx);
} slp_gsusb_transport_ops_t;

/// A transport: operations + their context (borrowed by the driver until deinit).
typedef struct slp_gsusb_transport {
    const slp_gsusb_transport_ops_t *ops;
    void *ctx;
} slp_gsusb_transport_t;

// =======================================================================================
// Driver

/// Driver state.
typedef enum slp_gsusb_state {
    SLP_GSUSB_CLOSED = 0,  ///< not started, stopped, or a start-up failed
    SLP_GSUSB_RUNNING = 1, ///< channel started: send/poll work
    SLP_GSUSB_DOWN = 2,    ///< the device vanished (or failed repeatedly): reopen the transport
                          ///< and call slp_gsusb_start() again
} slp_gsusb_state_t;

/// Extra facts about a received frame.
typedef struct slp_gsusb_rx_info {
    uint64_t now_us;        ///< time of the poll call that read it
    uint32_t timestamp_us;  ///< device timestamp (valid when has_timestamp)
    bool has_timestamp;
    bool overflow;          ///< the device reported an RX FIFO overflow with this frame
} slp_gsusb_rx_info_t;

/// A frame from the bus (or an error frame: SL_CAN_FLAG_ERR, class bits in `id`, details in
/// data[] per linux/can/error.h). `f` and `info` are valid during the call only.
typedef void (*slp_gsusb_on_rx_fn)(void *ctx, const sl_can_frame_t *f, const slp_gsusb_rx_info_t *info);

/// A transmitted frame left the window (confirmed, timed out or dropped). `latency_us` is
/// the time from the bulk OUT to the poll call that saw the echo (0 unless CONFIRMED).
typedef void (*slp_gsusb_on_tx_done_fn)(void *ctx, const sl_can_frame_t *f, uint32_t tag,
                                       slp_gsusb_tx_result_t result, uint64_t latency_us);

/// Configuration. Start from slp_gsusb_cfg_defaults().
typedef struct slp_gsusb_cfg {
    uint32_t bitrate;               ///< bit/s (default 500000)
    uint16_t sample_point_permille; ///< 0 = slp_gsusb_default_sample_point(bitrate)
    uint8_t channel;                ///< CAN channel (default 0)
    uint32_t mode_flags;            ///< SLP_GSUSB_MODE_FLAGS_ALLOWED bits (listen-only, loop-back
                                    ///< ...); each must be offered by the device. Default 0
    bool hw_timestamp;              ///< ask for 24-byte frames with device us timestamps when
                                    ///< the device offers them (default false)
    bool reset_first;               ///< send MODE RESET before BITTIMING (default true): stops a
                                    ///< channel left running by a process that died; a device
                                    ///< that stalls it is tolerated (counted)
    uint8_t max_in_flight;          ///< transmit window (default 10, <= SLP_GSUSB_MAX_IN_FLIGHT)
    uint32_t echo_timeout_ms;       ///< no echo this long: frame unconfirmed (default 1000)
    uint32_t control_timeout_ms;    ///< per vendor request (default 1000, as the kernel)
    uint32_t bulk_out_timeout_ms;   ///< longest a send may block on a busy device (default 100)
    uint16_t rx_budget;             ///< IN packets handled per poll at most (default 64)
    uint8_t io_error_limit;         ///< consecutive transfer errors that count as the device
                                    ///< being gone (default 3)
    slp_gsusb_on_rx_fn on_rx;        ///< optional
    slp_gsusb_on_tx_done_fn on_tx_done; ///< optional
    void *ctx;                      ///< passed to the callbacks
} slp_gsusb_cfg_t;

/// Counters since init (never reset by start/stop). Read-only to the application.
typedef struct slp_gsusb_stats {
    uint32_t starts;            ///< successful start-ups
    uint32_t start_failures;    ///< start-ups that failed (see last_error)
    uint32_t ctrl_stalls;       ///< control requests the device refused (stall)
    uint32_t ctrl_errors;       ///< control requests that timed out or failed otherwise
    uint32_t tx_frames;         ///< frames handed to the device (bulk OUT done)
    uint32_t tx_confirmed;      ///< ... and echoed (transmitted on the bus)
    uint32_t tx_unconfirmed;    ///< ... no echo within echo_timeout_ms
    uint32_t tx_dropped;        ///< ... given up in flight (device vanished, stop)
    uint32_t tx_window_full;    ///< sends refused: max_in_flight frames in flight
    uint32_t tx_timeouts;       ///< bulk OUT timed out (device not accepting): not sent
    uint32_t tx_errors;         ///< bulk OUT failed otherwise: not sent
    uint32_t tx_retries;        ///< bulk OUT repeated after a stall was cleared
    uint32_t stalls_out;        ///< bulk OUT endpoint halted
    uint32_t stalls_in;         ///< bulk IN endpoint halted
    uint32_t clear_halts;       ///< successful clear_halt calls
    uint32_t clear_halt_failures;
    uint32_t rx_frames;         ///< data/remote frames received (delivered to on_rx)
    uint32_t rx_error_frames;   ///< error frames received (delivered to on_rx)
    uint32_t rx_overflows;      ///< frames carrying the device's OVERFLOW flag
    uint32_t rx_malformed;      ///< IN packets too short / bad dlc / FD: dropped
    uint32_t rx_other_channel;  ///< frames of another channel: dropped
    uint32_t rx_io_errors;      ///< bulk IN failures (not stalls)
    uint32_t echo_unknown;      ///< echoes with an id not in flight
    uint32_t echo_mismatch;     ///< echoes whose can_id/dlc/data differ from the frame in
                                ///< flight under that id: a late echo of an earlier frame
                                ///< (its id timed out and was reused) or a bogus one. Not a
                                ///< confirmation: the frame in flight keeps waiting
    uint32_t bus_off;           ///< error frames with the BUSOFF class
    uint32_t err_passive;       ///< error frames reporting RX/TX error-passive
    uint32_t err_warning;       ///< error frames reporting RX/TX warning
    uint32_t vanished;          ///< times the device was found gone (state -> DOWN)
} slp_gsusb_stats_t;

/// Driver instance. Caller-allocated; fields read-only to the application.
typedef struct slp_gsusb {
    slp_gsusb_cfg_t cfg;
    slp_gsusb_transport_t tr;
    slp_gsusb_state_t state;
    slp_gsusb_device_config_t dev_cfg;  ///< from the last start-up
    slp_gsusb_bt_const_t bt_const;      ///< from the last start-up
    slp_gsusb_bt_result_t timing;       ///< what BITTIMING programmed
    uint32_t mode_flags_sent;          ///< MODE.flags of the START
    unsigned rx_fmt;                   ///< SLP_GSUSB_FMT_TIMESTAMP or 0
    unsigned tx_fmt;                   ///< SLP_GSUSB_FMT_QUIRK or 0
    uint8_t io_errors_in_row;
    slp_gsusb_echo_t echo;
    slp_gsusb_stats_t stats;
    char last_error[160];              ///< first problem of the last start-up ("" = none)
} slp_gsusb_t;

/// Defaults listed in slp_gsusb_cfg_t. O(1).
void slp_gsusb_cfg_defaults(slp_gsusb_cfg_t *cfg);

/// Initialise (state CLOSED). `tr` is copied; its context is borrowed until the caller stops
/// using `d`. @return SL_OK or SL_ERR_ARG (NULL, ops missing, bitrate 0, window too large,
/// mode flags outside SLP_GSUSB_MODE_FLAGS_ALLOWED). O(1).
sl_err_t slp_gsusb_init(slp_gsusb_t *d, const slp_gsusb_cfg_t *cfg, const slp_gsusb_transport_t *tr);

/// Replace the transport (after the sink reopened the USB device). O(1).
void slp_gsusb_set_transport(slp_gsusb_t *d, const slp_gsusb_transport_t *tr);

/// The start-up sequence (CAN_AND_USB.md s.1.4), each a vendor control request:
/// HOST_FORMAT (0x0000beef) -> DEVICE_CONFIG (channel count) -> BT_CONST (clock, limits,
/// features) -> [MODE RESET] -> BITTIMING -> MODE START (flags: cfg.mode_flags, plus
/// HW_TIMESTAMP when asked for and offered). Valid in CLOSED and DOWN; anything still in
/// flight is dropped first. Blocks for at most 6 x control_timeout_ms.
/// @return SL_OK (RUNNING); SL_ERR_PORT (a request was refused/stalled, timed out or failed,
///         or the device vanished: DOWN); SL_ERR_MALFORMED (short or nonsensical answers);
///         SL_ERR_RANGE (the bit rate cannot be produced: see last_error for the numbers);
///         SL_ERR_ARG (channel not present, mode flags not offered); SL_ERR_STATE (RUNNING).
///         On failure `last_error` names the request and the reason.
sl_err_t slp_gsusb_start(slp_gsusb_t *d, uint64_t now_us);

/// Transmit one frame (expired echoes are collected first). Blocks for at most
/// bulk_out_timeout_ms (twice that when a stall is cleared and the frame retried).
/// @return SL_OK (on the wire; the echo will confirm it, see on_tx_done);
///         SL_ERR_BUSY (not sent: window full or the device did not accept it in time);
///         SL_ERR_PORT (not sent: transfer failed; when the device is gone the state is DOWN);
///         SL_ERR_STATE (not RUNNING); SL_ERR_ARG (bad frame).
sl_err_t slp_gsusb_send(slp_gsusb_t *d, const sl_can_frame_t *f, uint32_t tag, uint64_t now_us);

/// Receive: wait at most `timeout_ms` for the first IN packet, then take what is already
/// there (up to rx_budget packets): echoes confirm frames (only when the echoed can_id,
/// dlc and data equal the frame in flight under that echo id, so a late echo can never
/// confirm the wrong frame), RX/error frames go to on_rx.
/// Then expire echoes older than echo_timeout_ms at `now_us`. A halted IN endpoint, or an
/// OUT endpoint the transport reports stalled, is cleared (counted). @return packets handled (>= 0), SL_ERR_PORT (the device vanished in
/// this call: DOWN) or SL_ERR_STATE (not RUNNING; nothing done).
sl_ssize_t slp_gsusb_poll(slp_gsusb_t *d, uint32_t timeout_ms, uint64_t now_us);

/// Read the controller state (GET_STATE; only when the device offers it).
/// @return SL_OK, SL_ERR_STATE (not RUNNING or not offered), SL_ERR_PORT, SL_ERR_MALFORMED.
sl_err_t slp_gsusb_get_state(slp_gsusb_t *d, slp_gsusb_can_state_t *out);

/// Stop: MODE RESET when RUNNING (errors ignored: the device may be gone), drop what is in
/// flight (on_tx_done DROPPED), state CLOSED. Idempotent. O(window) + one request.
void slp_gsusb_stop(slp_gsusb_t *d);

/// The device is known to be gone: drop what is in flight, state DOWN (counted once). O(window).
void slp_gsusb_mark_down(slp_gsusb_t *d);

/// Frames in flight (waiting for their echo). O(1).
uint8_t slp_gsusb_in_flight(const slp_gsusb_t *d);

/// Milliseconds until the oldest frame in flight times out (rounded up), -1 when none. O(window).
int slp_gsusb_next_timeout_ms(const slp_gsusb_t *d, uint64_t now_us);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_PORT_GSUSB_PROTO_H
