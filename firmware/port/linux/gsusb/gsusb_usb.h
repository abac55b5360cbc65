// SPDX-License-Identifier: MIT
/// @file gsusb_usb.h
/// @brief libusb-1.0 transport for gs_usb (candleLight) adapters: finds, claims and talks to
///        the device behind the `slp_gsusb_transport_t` seam of gsusb_proto.h.
///
/// What it does:
/// - finds the adapter by VID:PID, by bus-port ("1-1", "3-2.4": the sysfs name), or the
///   first device with a known gs_usb id (slp_gsusb_known_ids());
/// - detaches the kernel driver (gs_usb) when it is bound, claims interface 0, and on close
///   releases it and re-attaches the kernel driver (the kernel re-probes the device);
/// - takes the bulk endpoints from the interface descriptor (first bulk IN / OUT), falling
///   back to 0x81 / 0x02 (`eps_from_descriptor` false) when the descriptor lists none;
/// - keeps SLP_GSUSB_USB_IN_XFERS bulk IN transfers queued at all times (like the kernel's
///   RX URBs), so the device can always deliver echoes and RX frames; `bulk_in` hands out
///   the completed packets in order and resubmits the transfer;
/// - sends bulk OUT asynchronously: `bulk_out` submits and returns at once (OK = handed to
///   the USB stack). A transfer that later fails is reported on the next call: a stall
///   makes the next `bulk_out` return STALL (and `out_stalled` true); `clear_halt(OUT)`
///   then clears the endpoint and resubmits the stalled frames in their original order,
///   so nothing is lost or reordered. A device that does not take a frame within
///   `out_timeout_ms` loses it (counted in out_timeouts; the driver's echo timeout reports
///   it unconfirmed);
/// - a vanished device (unplug, reset, gadget unbound): every call returns NO_DEVICE.
///   Close it and open again (slp_gsusb_sink does that periodically).
///
/// Blocking: `bulk_out` and `bulk_in` with timeout 0 never block (libusb events are handled
/// with a zero timeout); control requests and clear_halt are synchronous (bounded by their
/// timeouts: a few ms with a healthy adapter). Not thread-safe: one thread per instance
/// (and per libusb context: each instance has its own).
///
/// Memory: slp_gsusb_usb_t is about 6 KB (transfer buffers inside); libusb allocates its
/// transfer structs at open and frees them at close.
#ifndef SHADOWLEAN_PORT_GSUSB_USB_H
#define SHADOWLEAN_PORT_GSUSB_USB_H

#include <poll.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "gsusb_proto.h"
#include "shadowlean/sl_err.h"

#ifdef __cplusplus
extern "C" {
#endif

struct libusb_context;
struct libusb_device_handle;
struct libusb_transfer;

#define SLP_GSUSB_USB_IN_XFERS 8U                               ///< bulk IN transfers kept queued
#define SLP_GSUSB_USB_OUT_XFERS (SLP_GSUSB_MAX_IN_FLIGHT + 4U)   ///< bulk OUT transfer slots
#define SLP_GSUSB_USB_IN_BUF 512U                               ///< one packet (high-speed max)
#define SLP_GSUSB_USB_MAX_PORTS 7U                              ///< USB hub depth limit

/// Which adapter. Parse one with slp_gsusb_usb_parse_selector().
typedef struct slp_gsusb_usb_sel {
    bool by_id;        ///< match vid:pid
    uint16_t vid, pid;
    bool by_port;      ///< match bus + port path
    uint8_t bus;
    uint8_t ports[SLP_GSUSB_USB_MAX_PORTS];
    uint8_t n_ports;
} slp_gsusb_usb_sel_t;

/// Parse "VID:PID" (hex, "1d50:606f"), "BUS-PORT[.PORT...]" (decimal, "1-1", "3-2.4"), or
/// NULL / "" (first adapter with a known gs_usb id).
/// @return SL_OK or SL_ERR_ARG (anything else). O(strlen).
sl_err_t slp_gsusb_usb_parse_selector(const char *s, slp_gsusb_usb_sel_t *out);

/// Counters since init. Read-only.
typedef struct slp_gsusb_usb_stats {
    uint32_t opens;             ///< successful opens
    uint32_t open_failures;     ///< opens that failed (see `err`)
    uint32_t kernel_detaches;   ///< kernel driver detached at open
    uint32_t kernel_reattaches; ///< kernel driver re-attached at close
    uint32_t reattach_failures; ///< ... failed (device gone: expected)
    uint32_t in_packets;        ///< bulk IN packets handed to the driver
    uint32_t in_stalls;         ///< bulk IN transfers that ended in a stall
    uint32_t in_errors;         ///< bulk IN transfers that failed otherwise
    uint32_t out_submitted;     ///< bulk OUT transfers submitted (resubmits included)
    uint32_t out_done;          ///< ... completed
    uint32_t out_stalls;        ///< ... ended in a stall (kept for resubmission)
    uint32_t out_resubmits;     ///< ... resubmitted after clear_halt
    uint32_t out_timeouts;      ///< ... not taken by the device within out_timeout_ms (lost)
    uint32_t out_errors;        ///< ... failed otherwise (lost)
    uint32_t clear_halts;       ///< libusb_clear_halt calls that succeeded
    uint32_t no_device;         ///< times the device was found gone
    uint32_t stuck_transfers;   ///< transfers still active when close gave up waiting (leaked)
} slp_gsusb_usb_stats_t;

/// One bulk IN transfer.
typedef struct slp_gsusb_usb_in {
    struct slp_gsusb_usb *u;
    struct libusb_transfer *t;
    uint8_t state;                 ///< idle / active / done (internal)
    uint8_t buf[SLP_GSUSB_USB_IN_BUF];
} slp_gsusb_usb_in_t;

/// One bulk OUT transfer.
typedef struct slp_gsusb_usb_out {
    struct slp_gsusb_usb *u;
    struct libusb_transfer *t;
    uint8_t state;                 ///< idle / active / stalled (internal)
    uint32_t seq;                  ///< submission order (stalled frames are resent in order)
    uint8_t len;
    uint8_t buf[SLP_GSUSB_FRAME_MAX_BYTES];
} slp_gsusb_usb_out_t;

/// Transport instance. Caller-allocated; fields read-only to the application.
typedef struct slp_gsusb_usb {
    struct libusb_context *ctx;
    struct libusb_device_handle *h;
    slp_gsusb_usb_sel_t sel;
    uint32_t out_timeout_ms;       ///< per bulk OUT transfer (default 1000; gsusb_sink sets
                                   ///< it to the echo timeout)
    uint16_t vid, pid;             ///< of the opened device
    char where[32];                ///< "bus-port" of the opened device, e.g. "1-1"
    uint8_t ep_in, ep_out;
    uint16_t mps_in;
    bool eps_from_descriptor;
    bool detached;                 ///< we detached the kernel driver (re-attach at close)
    bool claimed;
    bool gone;
    bool in_halted;
    bool out_halted;
    uint32_t out_seq;
    uint32_t open_attempts;        ///< every attempt after the first uses a fresh libusb context
    slp_gsusb_usb_in_t in[SLP_GSUSB_USB_IN_XFERS];
    uint8_t done_q[SLP_GSUSB_USB_IN_XFERS]; ///< completed IN transfers, oldest first
    uint8_t done_head, done_count;
    slp_gsusb_usb_out_t out[SLP_GSUSB_USB_OUT_XFERS];
    slp_gsusb_usb_stats_t stats;
    char err[192];                 ///< why the last open failed ("" = no failure)
} slp_gsusb_usb_t;

/// Initialise: a private libusb context. @return SL_OK or SL_ERR_PORT (libusb_init failed:
/// `err` says why). Nothing is opened yet.
sl_err_t slp_gsusb_usb_init(slp_gsusb_usb_t *u);

/// Find, open, detach the kernel driver, claim interface 0, find the endpoints, queue the
/// IN transfers. Every call after the first re-creates the libusb context first, so the
/// bus is rescanned even where no udev daemon delivers hotplug events. @return SL_OK; SL_ERR_PORT (no matching device, permission denied,
/// interface busy, ...: `err` says which, with the device); SL_ERR_STATE (already open);
/// SL_ERR_ARG. Cost: one bus scan plus a few descriptor reads.
sl_err_t slp_gsusb_usb_open(slp_gsusb_usb_t *u, const slp_gsusb_usb_sel_t *sel);

/// True while a device is open (it may have vanished since: see `gone`).
bool slp_gsusb_usb_is_open(const slp_gsusb_usb_t *u);

/// Cancel the transfers (waits up to 500 ms for them), release the interface, re-attach
/// the kernel driver if we detached it, close. Idempotent; fine on a vanished device.
void slp_gsusb_usb_close(slp_gsusb_usb_t *u);

/// Close and free the libusb context. Idempotent.
void slp_gsusb_usb_deinit(slp_gsusb_usb_t *u);

/// The transport for slp_gsusb_init() (ops + this instance; borrowed).
slp_gsusb_transport_t slp_gsusb_usb_transport(slp_gsusb_usb_t *u);

/// File descriptors libusb wants polled (for a caller's poll() loop): up to `cap` entries
/// written to `fds`. When one is ready, call the driver's poll. They belong to the current
/// libusb context: ask again after every (re)open. @return how many. O(fds).
size_t slp_gsusb_usb_pollfds(slp_gsusb_usb_t *u, struct pollfd *fds, size_t cap);

/// Print every USB device with a known gs_usb id ("1d50:606f at 1-1 (bound to gs_usb)")
/// into `buf` (one per line). @return the number found, or -1 when libusb failed.
int slp_gsusb_usb_list(slp_gsusb_usb_t *u, char *buf, size_t cap);

#ifdef __cplusplus
}
#endif

#endif // SHADOWLEAN_PORT_GSUSB_USB_H
