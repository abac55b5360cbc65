// SPDX-License-Identifier: MIT
// libusb-1.0 transport for gs_usb adapters (see gsusb_usb.h).
#include "gsusb_usb.h"

#include <libusb-1.0/libusb.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

enum { X_IDLE = 0, X_ACTIVE = 1, X_DONE = 2, X_STALLED = 3 };

static uint64_t mono_ms(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000U + (uint64_t)ts.tv_nsec / 1000000U;
}

static void set_err(slp_gsusb_usb_t *u, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void set_err(slp_gsusb_usb_t *u, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(u->err, sizeof u->err, fmt, ap);
    va_end(ap);
}

// ---------------------------------------------------------------------------------------
// Selector

static bool parse_uint(const char **p, unsigned base, unsigned long max, unsigned long *out)
{
    char *end = NULL;
    if (**p == '\0' || **p == '-' || **p == '+' || **p == ' ') {
        return false;
    }
    unsigned long v = strtoul(*p, &end, (int)base);
    if (end == *p || v > max) {
        return false;
    }
    *p = end;
    *out = v;
    return true;
}

sl_err_t slp_gsusb_usb_parse_selector(const char *s, slp_gsusb_usb_sel_t *out)
{
    if (out == NULL) {
        return SL_ERR_ARG;
    }
    memset(out, 0, sizeof *out);
    if (s == NULL || *s == '\0') {
        return SL_OK;
    }
    const char *p = s;
    unsigned long a = 0;
    unsigned long b = 0;
    if (strchr(s, ':') != NULL) {
        if (!parse_uint(&p, 16, 0xFFFF, &a) || *p++ != ':' || !parse_uint(&p, 16, 0xFFFF, &b) ||
            *p != '\0') {
            return SL_ERR_ARG;
        }
        out->by_id = true;
        out->vid = (uint16_t)a;
        out->pid = (uint16_t)b;
        return SL_OK;
    }
    if (!parse_uint(&p, 10, 255, &a) || *p++ != '-') {
        return SL_ERR_ARG;
    }
    out->bus = (uint8_t)a;
    for (;;) {
        if (out->n_ports >= SLP_GSUSB_USB_MAX_PORTS || !parse_uint(&p, 10, 255, &b) || b == 0U) {
            return SL_ERR_ARG;
        }
        out->ports[out->n_ports++] = (uint8_t)b;
        if (*p == '\0') {
            break;
        }
        if (*p++ != '.') {
            return SL_ERR_ARG;
        }
    }
    out->by_port = true;
    return SL_OK;
}

static void port_name(libusb_device *dev, char *buf, size_t cap)
{
    uint8_t ports[SLP_GSUSB_USB_MAX_PORTS];
    int n = libusb_get_port_numbers(dev, ports, (int)sizeof ports);
    int k = snprintf(buf, cap, "%u-", (unsigned)libusb_get_bus_number(dev));
    for (int i = 0; i < n && k > 0 && (size_t)k < cap; i++) {
        k += snprintf(buf + k, cap - (size_t)k, i == 0 ? "%u" : ".%u", (unsigned)ports[i]);
    }
    if (n <= 0 && k > 0 && (size_t)k < cap) {
        (void)snprintf(buf + k, cap - (size_t)k, "0"); // root hub
    }
}

static bool matches(const slp_gsusb_usb_sel_t *sel, libusb_device *dev,
                    const struct libusb_device_descriptor *dd)
{
    if (sel->by_id) {
        return dd->idVendor == sel->vid && dd->idProduct == sel->pid;
    }
    if (sel->by_port) {
        uint8_t ports[SLP_GSUSB_USB_MAX_PORTS];
        int n = libusb_get_port_numbers(dev, ports, (int)sizeof ports);
        return libusb_get_bus_number(dev) == sel->bus && n == (int)sel->n_ports &&
               memcmp(ports, sel->ports, sel->n_ports) == 0;
    }
    return slp_gsusb_is_known_id(dd->idVendor, dd->idProduct);
}

static void sel_text(const slp_gsusb_usb_sel_t *sel, char *buf, size_t cap)
{
    if (sel->by_id) {
        (void)snprintf(buf, cap, "%04x:%04x", (unsigned)sel->vid, (unsigned)sel->pid);
    } else if (sel->by_port) {
        int k = snprintf(buf, cap, "%u-", (unsigned)sel->bus);
        for (uint8_t i = 0; i < sel->n_ports && k > 0 && (size_t)k < cap; i++) {
            k += snprintf(buf + k, cap - (size_t)k, i == 0 ? "%u" : ".%u", (unsigned)sel->ports[i]);
        }
    } else {
        (void)snprintf(buf, cap, "any known gs_usb id");
    }
}

// ---------------------------------------------------------------------------------------
// Init / open / close

sl_err_t slp_gsusb_usb_init(slp_gsusb_usb_t *u)
{
    if (u == NULL) {
        return SL_ERR_ARG;
    }
    memset(u, 0, sizeof *u);
    u->out_timeout_ms = 1000U;
    int r = libusb_init(&u->ctx);
    if (r != 0) {
        u->ctx = NULL;
        set_err(u, "libusb_init failed: %s", libusb_error_name(r));
        return SL_ERR_PORT;
    }
    return SL_OK;
}

bool slp_gsusb_usb_is_open(const slp_gsusb_usb_t *u)
{
    return u != NULL && u->h != NULL;
}

static void LIBUSB_CALL in_cb(struct libusb_transfer *t)
{
    slp_gsusb_usb_in_t *x = t->user_data;
    slp_gsusb_usb_t *u = x->u;
    x->state = X_DONE;
    if (u->done_count < SLP_GSUSB_USB_IN_XFERS) {
        uint8_t idx = (uint8_t)(x - u->in);
        u->done_q[(u->done_head + u->done_count) % SLP_GSUSB_USB_IN_XFERS] = idx;
        u->done_count++;
    }
}

static void LIBUSB_CALL out_cb(struct libusb_transfer *t)
{
    slp_gsusb_usb_out_t *x = t->user_data;
    slp_gsusb_usb_t *u = x->u;
    switch (t->status) {
    case LIBUSB_TRANSFER_COMPLETED:
        if (t->actual_length == t->length) {
            x->state = X_IDLE;
            u->stats.out_done++;
        } else {
            x->state = X_IDLE;
            u->stats.out_errors++;
        }
        break;
    case LIBUSB_TRANSFER_STALL:
        x->state = X_STALLED; // kept: resubmitted in order by clear_halt(OUT)
        u->out_halted = true;
        u->stats.out_stalls++;
        break;
    case LIBUSB_TRANSFER_CANCELLED:
        if (t->actual_length == t->length) {
            x->state = X_IDLE; // it went out before the cancel took effect
            u->stats.out_done++;
        } else {
            // Cancelled by clear_halt (resent in order) or by close (freed there).
            x->state = X_STALLED;
        }
        break;
    case LIBUSB_TRANSFER_NO_DEVICE:
        x->state = X_IDLE;
        if (!u->gone) {
            u->stats.no_device++;
        }
        u->gone = true;
        break;
    case LIBUSB_TRANSFER_TIMED_OUT:
        x->state = X_IDLE;
        u->stats.out_timeouts++;
        break;
    case LIBUSB_TRANSFER_ERROR:
    case LIBUSB_TRANSFER_OVERFLOW:
    default:
        x->state = X_IDLE;
        u->stats.out_errors++;
        break;
    }
}

static void mark_gone(slp_gsusb_usb_t *u)
{
    if (!u->gone) {
        u->stats.no_device++;
    }
    u->gone = true;
}

static void submit_in(slp_gsusb_usb_t *u, slp_gsusb_usb_in_t *x)
{
    if (u->gone || x->t == NULL) {
        x->state = X_IDLE;
        return;
    }
    libusb_fill_bulk_transfer(x->t, u->h, u->ep_in, x->buf, (int)u->mps_in, in_cb, x, 0);
    int r = libusb_submit_transfer(x->t);
    if (r == 0) {
        x->state = X_ACTIVE;
        return;
    }
    x->state = X_IDLE;
    if (r == LIBUSB_ERROR_NO_DEVICE) {
        mark_gone(u);
    } else {
        u->stats.in_errors++;
    }
}

static int submit_out(slp_gsusb_usb_t *u, slp_gsusb_usb_out_t *x)
{
    libusb_fill_bulk_transfer(x->t, u->h, u->ep_out, x->buf, (int)x->len, out_cb, x,
                              u->out_timeout_ms);
    int r = libusb_submit_transfer(x->t);
    if (r == 0) {
        x->state = X_ACTIVE;
        u->stats.out_submitted++;
    } else {
        x->state = X_IDLE;
        if (r == LIBUSB_ERROR_NO_DEVICE) {
            mark_gone(u);
        } else {
            u->stats.out_errors++;
        }
    }
    return r;
}

static void handle_events_ms(slp_gsusb_usb_t *u, uint32_t ms)
{
    struct timeval tv = {(time_t)(ms / 1000U), (suseconds_t)((ms % 1000U) * 1000U)};
    (void)libusb_handle_events_timeout_completed(u->ctx, &tv, NULL);
}

static size_t active_in(const slp_gsusb_usb_t *u)
{
    size_t n = 0;
    for (size_t i = 0; i < SLP_GSUSB_USB_IN_XFERS; i++) {
        n += u->in[i].state == X_ACTIVE ? 1U : 0U;
    }
    return n;
}

static size_t active_out(const slp_gsusb_usb_t *u)
{
    size_t n = 0;
    for (size_t i = 0; i < SLP_GSUSB_USB_OUT_XFERS; i++) {
        n += u->out[i].state == X_ACTIVE ? 1U : 0U;
    }
    return n;
}

// Wait (handling events) until `count(u)` is 0 or `ms` passed.
static void wait_idle(slp_gsusb_usb_t *u, size_t (*count)(const slp_gsusb_usb_t *), uint32_t ms)
{
    uint64_t end = mono_ms() + ms;
    while (count(u) > 0U) {
        uint64_t now = mono_ms();
        if (now >= end) {
            break;
        }
        handle_events_ms(u, (uint32_t)(end - now));
    }
}

static void find_endpoints(slp_gsusb_usb_t *u, libusb_device *dev)
{
    u->ep_in = (uint8_t)SLP_GSUSB_EP_IN_DEFAULT;
    u->ep_out = (uint8_t)SLP_GSUSB_EP_OUT_DEFAULT;
    u->mps_in = 64;
    u->eps_from_descriptor = false;
    struct libusb_config_descriptor *cfg = NULL;
    if (libusb_get_active_config_descriptor(dev, &cfg) != 0 || cfg == NULL) {
        return;
    }
    bool have_in = false;
    bool have_out = false;
    for (uint8_t i = 0; i < cfg->bNumInterfaces; i++) {
        const struct libusb_interface *itf = &cfg->interface[i];
        if (itf->num_altsetting < 1 || itf->altsetting[0].bInterfaceNumber != SLP_GSUSB_INTERFACE) {
            continue;
        }
        const struct libusb_interface_descriptor *alt = &itf->altsetting[0];
        for (uint8_t e = 0; e < alt->bNumEndpoints; e++) {
            const struct libusb_endpoint_descriptor *ep = &alt->endpoint[e];
            if ((ep->bmAttributes & 0x03U) != LIBUSB_TRANSFER_TYPE_BULK) {
                continue;
            }
            if ((ep->bEndpointAddress & LIBUSB_ENDPOINT_IN) != 0U) {
                if (!have_in) {
                    u->ep_in = ep->bEndpointAddress;
                    u->mps_in = ep->wMaxPacketSize;
                    have_in = true;
                }
            } else if (!have_out) {
                u->ep_out = ep->bEndpointAddress;
                have_out = true;
            }
        }
    }
    libusb_free_config_descriptor(cfg);
    u->eps_from_descriptor = have_in && have_out;
    if (!u->eps_from_descriptor) {
        u->ep_in = (uint8_t)SLP_GSUSB_EP_IN_DEFAULT;
        u->ep_out = (uint8_t)SLP_GSUSB_EP_OUT_DEFAULT;
        u->mps_in = 64;
    }
    if (u->mps_in < SLP_GSUSB_FRAME_MAX_BYTES || u->mps_in > SLP_GSUSB_USB_IN_BUF) {
        u->mps_in = 64; // nonsense descriptor: a full-speed packet holds any classic frame
    }
}

static void free_transfers(slp_gsusb_usb_t *u)
{
    for (size_t i = 0; i < SLP_GSUSB_USB_IN_XFERS; i++) {
        if (u->in[i].t != NULL && u->in[i].state != X_ACTIVE) {
            libusb_free_transfer(u->in[i].t);
        } else if (u->in[i].t != NULL) {
            u->stats.stuck_transfers++; // cannot be freed while libusb owns it
        }
        u->in[i].t = NULL;
        u->in[i].state = X_IDLE;
    }
    for (size_t i = 0; i < SLP_GSUSB_USB_OUT_XFERS; i++) {
        if (u->out[i].t != NULL && u->out[i].state != X_ACTIVE) {
            libusb_free_transfer(u->out[i].t);
        } else if (u->out[i].t != NULL) {
            u->stats.stuck_transfers++;
        }
        u->out[i].t = NULL;
        u->out[i].state = X_IDLE;
    }
    u->done_head = 0;
    u->done_count = 0;
}

static sl_err_t open_fail(slp_gsusb_usb_t *u)
{
    u->stats.open_failures++;
    slp_gsusb_usb_close(u);
    return SL_ERR_PORT;
}

sl_err_t slp_gsusb_usb_open(slp_gsusb_usb_t *u, const slp_gsusb_usb_sel_t *sel)
{
    if (u == NULL || sel == NULL) {
        return SL_ERR_ARG;
    }
    if (u->ctx == NULL && u->open_attempts == 0U) {
        set_err(u, "libusb not initialised");
        return SL_ERR_STATE;
    }
    if (u->h != NULL) {
        return SL_ERR_STATE;
    }
    u->err[0] = '\0';
    if (u->open_attempts++ > 0U) {
        // A fresh context rescans the bus. The old one's device list is only updated by
        // hotplug events, which never come where no udev daemon runs (containers, the test
        // VM): a device that re-enumerated after an unplug would stay invisible.
        if (u->ctx != NULL) {
            libusb_exit(u->ctx);
        }
        u->ctx = NULL;
        int r = libusb_init(&u->ctx);
        if (r != 0) {
            u->ctx = NULL;
            set_err(u, "libusb_init failed: %s", libusb_error_name(r));
            u->stats.open_failures++;
            return SL_ERR_PORT;
        }
    }
    u->sel = *sel;
    u->gone = false;
    u->in_halted = false;
    u->out_halted = false;
    u->detached = false;
    u->claimed = false;
    char want[48];
    sel_text(sel, want, sizeof want);

    libusb_device **list = NULL;
    ssize_t n = libusb_get_device_list(u->ctx, &list);
    if (n < 0) {
        set_err(u, "cannot list USB devices: %s", libusb_error_name((int)n));
        u->stats.open_failures++;
        return SL_ERR_PORT;
    }
    libusb_device *dev = NULL;
    int open_rc = 0;
    for (ssize_t i = 0; i < n; i++) {
        struct libusb_device_descriptor dd;
        if (libusb_get_device_descriptor(list[i], &dd) != 0 || !matches(sel, list[i], &dd)) {
            continue;
        }
        open_rc = libusb_open(list[i], &u->h);
        if (open_rc == 0) {
            dev = list[i];
            u->vid = dd.idVendor;
            u->pid = dd.idProduct;
            port_name(dev, u->where, sizeof u->where);
            break;
        }
        u->h = NULL;
    }
    if (dev == NULL) {
        if (open_rc != 0) {
            set_err(u, "gs_usb adapter (%s) found but cannot be opened: %s%s", want,
                    libusb_error_name(open_rc),
                    open_rc == LIBUSB_ERROR_ACCESS ? " (run as root or add a udev rule)" : "");
        } else {
            set_err(u, "no gs_usb adapter found (%s)", want);
        }
        libusb_free_device_list(list, 1);
        u->stats.open_failures++;
        return SL_ERR_PORT;
    }
    find_endpoints(u, dev);
    libusb_free_device_list(list, 1);

    int r = libusb_kernel_driver_active(u->h, (int)SLP_GSUSB_INTERFACE);
    if (r == 1) {
        r = libusb_detach_kernel_driver(u->h, (int)SLP_GSUSB_INTERFACE);
        if (r != 0) {
            set_err(u, "%04x:%04x at %s: cannot detach the kernel driver: %s", u->vid, u->pid,
                    u->where, libusb_error_name(r));
            return open_fail(u);
        }
        u->detached = true;
        u->stats.kernel_detaches++;
    }
    r = libusb_claim_interface(u->h, (int)SLP_GSUSB_INTERFACE);
    if (r != 0) {
        set_err(u, "%04x:%04x at %s: cannot claim interface 0: %s%s", u->vid, u->pid, u->where,
                libusb_error_name(r), r == LIBUSB_ERROR_BUSY ? " (another program has it)" : "");
        return open_fail(u);
    }
    u->claimed = true;

    for (size_t i = 0; i < SLP_GSUSB_USB_IN_XFERS; i++) {
        u->in[i].u = u;
        u->in[i].state = X_IDLE;
        u->in[i].t = libusb_alloc_transfer(0);
        if (u->in[i].t == NULL) {
            set_err(u, "out of memory for libusb transfers");
            return open_fail(u);
        }
    }
    for (size_t i = 0; i < SLP_GSUSB_USB_OUT_XFERS; i++) {
        u->out[i].u = u;
        u->out[i].state = X_IDLE;
        u->out[i].t = libusb_alloc_transfer(0);
        if (u->out[i].t == NULL) {
            set_err(u, "out of memory for libusb transfers");
            return open_fail(u);
        }
    }
    u->done_head = 0;
    u->done_count = 0;
    for (size_t i = 0; i < SLP_GSUSB_USB_IN_XFERS; i++) {
        submit_in(u, &u->in[i]);
    }
    if (u->gone || active_in(u) == 0U) {
        set_err(u, "%04x:%04x at %s: cannot queue bulk IN transfers on 0x%02x", u->vid, u->pid,
                u->where, (unsigned)u->ep_in);
        return open_fail(u);
    }
    u->stats.opens++;
    return SL_OK;
}

void slp_gsusb_usb_close(slp_gsusb_usb_t *u)
{
    if (u == NULL || u->h == NULL) {
        return;
    }
    for (size_t i = 0; i < SLP_GSUSB_USB_IN_XFERS; i++) {
        if (u->in[i].state == X_ACTIVE) {
            (void)libusb_cancel_transfer(u->in[i].t);
        }
    }
    for (size_t i = 0; i < SLP_GSUSB_USB_OUT_XFERS; i++) {
        if (u->out[i].state == X_ACTIVE) {
            (void)libusb_cancel_transfer(u->out[i].t);
        }
    }
    wait_idle(u, active_in, 500U);
    wait_idle(u, active_out, 200U);
    free_transfers(u);
    if (u->claimed) {
        (void)libusb_release_interface(u->h, (int)SLP_GSUSB_INTERFACE);
        u->claimed = false;
    }
    if (u->detached) {
        int r = libusb_attach_kernel_driver(u->h, (int)SLP_GSUSB_INTERFACE);
        if (r == 0) {
            u->stats.kernel_reattaches++;
        } else {
            u->stats.reattach_failures++;
        }
        u->detached = false;
    }
    libusb_close(u->h);
    u->h = NULL;
    u->in_halted = false;
    u->out_halted = false;
}

void slp_gsusb_usb_deinit(slp_gsusb_usb_t *u)
{
    if (u == NULL) {
        return;
    }
    slp_gsusb_usb_close(u);
    if (u->ctx != NULL) {
        libusb_exit(u->ctx);
        u->ctx = NULL;
    }
}

// ---------------------------------------------------------------------------------------
// Transport operations

static slp_gsusb_io_t map_err(slp_gsusb_usb_t *u, int r)
{
    switch (r) {
    case LIBUSB_SUCCESS: return SLP_GSUSB_IO_OK;
    case LIBUSB_ERROR_TIMEOUT: return SLP_GSUSB_IO_TIMEOUT;
    case LIBUSB_ERROR_PIPE: return SLP_GSUSB_IO_STALL;
    case LIBUSB_ERROR_OVERFLOW: return SLP_GSUSB_IO_OVERFLOW;
    case LIBUSB_ERROR_NO_DEVICE:
        mark_gone(u);
        return SLP_GSUSB_IO_NO_DEVICE;
    default: return SLP_GSUSB_IO_ERROR;
    }
}

static slp_gsusb_io_t usb_control(slp_gsusb_usb_t *u, uint8_t rt, uint8_t breq, uint16_t wvalue,
                                 uint16_t windex, uint8_t *data, uint16_t len, uint32_t timeout_ms,
                                 size_t *transferred)
{
    *transferred = 0;
    if (u->h == NULL || u->gone) {
        return SLP_GSUSB_IO_NO_DEVICE;
    }
    int r = libusb_control_transfer(u->h, rt, breq, wvalue, windex, data, len,
                                    timeout_ms == 0U ? 1U : timeout_ms);
    if (r >= 0) {
        *transferred = (size_t)r;
        return SLP_GSUSB_IO_OK;
    }
    return map_err(u, r);
}

static slp_gsusb_io_t op_control_out(void *ctx, uint8_t rt, uint8_t breq, uint16_t wvalue,
                                    uint16_t windex, const uint8_t *data, uint16_t len,
                                    uint32_t timeout_ms, size_t *transferred)
{
    uint8_t buf[64];
    if (len > sizeof buf) {
        *transferred = 0;
        return SLP_GSUSB_IO_ERROR;
    }
    if (len > 0U) {
        memcpy(buf, data, len);
    }
    return usb_control(ctx, rt, breq, wvalue, windex, buf, len, timeout_ms, transferred);
}

static slp_gsusb_io_t op_control_in(void *ctx, uint8_t rt, uint8_t breq, uint16_t wvalue,
                                   uint16_t windex, uint8_t *data, uint16_t len,
                                   uint32_t timeout_ms, size_t *transferred)
{
    return usb_control(ctx, rt, breq, wvalue, windex, data, len, timeout_ms, transferred);
}

static slp_gsusb_io_t op_bulk_out(void *ctx, const uint8_t *data, size_t len, uint32_t timeout_ms,
                                 size_t *transferred)
{
    slp_gsusb_usb_t *u = ctx;
    *transferred = 0;
    if (u->h == NULL || u->gone) {
        return SLP_GSUSB_IO_NO_DEVICE;
    }
    if (len > SLP_GSUSB_FRAME_MAX_BYTES) {
        return SLP_GSUSB_IO_ERROR;
    }
    handle_events_ms(u, 0); // reap finished transfers (a stall or unplug shows up here)
    if (u->gone) {
        return SLP_GSUSB_IO_NO_DEVICE;
    }
    if (u->out_halted) {
        return SLP_GSUSB_IO_STALL;
    }
    uint64_t end = mono_ms() + timeout_ms;
    slp_gsusb_usb_out_t *x = NULL;
    for (;;) {
        for (size_t i = 0; i < SLP_GSUSB_USB_OUT_XFERS; i++) {
            if (u->out[i].state == X_IDLE) {
                x = &u->out[i];
                break;
            }
        }
        uint64_t now = mono_ms();
        if (x != NULL || now >= end || u->gone || u->out_halted) {
            break;
        }
        handle_events_ms(u, (uint32_t)(end - now));
    }
    if (u->gone) {
        return SLP_GSUSB_IO_NO_DEVICE;
    }
    if (u->out_halted) {
        return SLP_GSUSB_IO_STALL;
    }
    if (x == NULL) {
        return SLP_GSUSB_IO_TIMEOUT; // every slot busy: the device is not taking frames
    }
    memcpy(x->buf, data, len);
    x->len = (uint8_t)len;
    x->seq = u->out_seq++;
    int r = submit_out(u, x);
    if (r != 0) {
        return map_err(u, r);
    }
    *transferred = len;
    return SLP_GSUSB_IO_OK;
}

static slp_gsusb_io_t op_bulk_in(void *ctx, uint8_t *buf, size_t cap, uint32_t timeout_ms,
                                size_t *transferred)
{
    slp_gsusb_usb_t *u = ctx;
    *transferred = 0;
    if (u->h == NULL) {
        return SLP_GSUSB_IO_NO_DEVICE;
    }
    uint64_t end = mono_ms() + timeout_ms;
    bool waited = false;
    for (;;) {
        while (u->done_count > 0U) {
            uint8_t idx = u->done_q[u->done_head];
            u->done_head = (uint8_t)((u->done_head + 1U) % SLP_GSUSB_USB_IN_XFERS);
            u->done_count--;
            slp_gsusb_usb_in_t *x = &u->in[idx];
            struct libusb_transfer *t = x->t;
            size_t got = t->actual_length > 0 ? (size_t)t->actual_length : 0U;
            x->state = X_IDLE;
            if (got > 0U && (t->status == LIBUSB_TRANSFER_COMPLETED ||
                             t->status == LIBUSB_TRANSFER_CANCELLED ||
                             t->status == LIBUSB_TRANSFER_TIMED_OUT)) {
                size_t n = got < cap ? got : cap;
                memcpy(buf, x->buf, n);
                *transferred = n;
                u->stats.in_packets++;
                if (!u->in_halted) {
                    submit_in(u, x);
                }
                return got > cap ? SLP_GSUSB_IO_OVERFLOW : SLP_GSUSB_IO_OK;
            }
            switch (t->status) {
            case LIBUSB_TRANSFER_STALL:
                u->stats.in_stalls++;
                u->in_halted = true; // resubmitted by clear_halt(IN)
                return SLP_GSUSB_IO_STALL;
            case LIBUSB_TRANSFER_NO_DEVICE:
                mark_gone(u);
                return SLP_GSUSB_IO_NO_DEVICE;
            case LIBUSB_TRANSFER_OVERFLOW:
                u->stats.in_errors++;
                submit_in(u, x);
                return SLP_GSUSB_IO_OVERFLOW;
            case LIBUSB_TRANSFER_COMPLETED: // zero-length packet
                submit_in(u, x);
                continue;
            case LIBUSB_TRANSFER_CANCELLED:
            case LIBUSB_TRANSFER_TIMED_OUT:
                if (!u->in_halted) {
                    submit_in(u, x);
                }
                continue;
            case LIBUSB_TRANSFER_ERROR:
            default:
                u->stats.in_errors++;
                submit_in(u, x);
                return SLP_GSUSB_IO_ERROR;
            }
        }
        if (u->gone) {
            return SLP_GSUSB_IO_NO_DEVICE;
        }
        if (u->in_halted) {
            return SLP_GSUSB_IO_STALL;
        }
        uint64_t now = mono_ms();
        if (waited && now >= end) {
            return SLP_GSUSB_IO_TIMEOUT;
        }
        handle_events_ms(u, now >= end ? 0U : (uint32_t)(end - now));
        waited = true;
    }
}

static slp_gsusb_io_t op_clear_halt(void *ctx, bool in)
{
    slp_gsusb_usb_t *u = ctx;
    if (u->h == NULL || u->gone) {
        return SLP_GSUSB_IO_NO_DEVICE;
    }
    if (in) {
        for (size_t i = 0; i < SLP_GSUSB_USB_IN_XFERS; i++) {
            if (u->in[i].state == X_ACTIVE) {
                (void)libusb_cancel_transfer(u->in[i].t);
            }
        }
        wait_idle(u, active_in, 200U);
        // Keep completed packets (in order); forget the stalled/cancelled empty ones.
        uint8_t keep[SLP_GSUSB_USB_IN_XFERS];
        uint8_t nkeep = 0;
        for (uint8_t k = 0; k < u->done_count; k++) {
            uint8_t idx = u->done_q[(u->done_head + k) % SLP_GSUSB_USB_IN_XFERS];
            struct libusb_transfer *t = u->in[idx].t;
            if (t->actual_length > 0 && t->status != LIBUSB_TRANSFER_STALL &&
                t->status != LIBUSB_TRANSFER_NO_DEVICE) {
                keep[nkeep++] = idx;
            } else {
                u->in[idx].state = X_IDLE;
            }
        }
        memcpy(u->done_q, keep, nkeep);
        u->done_head = 0;
        u->done_count = nkeep;
        int r = libusb_clear_halt(u->h, u->ep_in);
        if (r != 0) {
            return map_err(u, r);
        }
        u->stats.clear_halts++;
        u->in_halted = false;
        for (size_t i = 0; i < SLP_GSUSB_USB_IN_XFERS; i++) {
            if (u->in[i].state == X_IDLE) {
                submit_in(u, &u->in[i]);
            }
        }
        return u->gone ? SLP_GSUSB_IO_NO_DEVICE : SLP_GSUSB_IO_OK;
    }
    // OUT: stop what is still queued (it would hit the halt too), clear, resend in order.
    for (size_t i = 0; i < SLP_GSUSB_USB_OUT_XFERS; i++) {
        if (u->out[i].state == X_ACTIVE) {
            (void)libusb_cancel_transfer(u->out[i].t);
        }
    }
    wait_idle(u, active_out, 200U);
    int r = libusb_clear_halt(u->h, u->ep_out);
    if (r != 0) {
        return map_err(u, r);
    }
    u->stats.clear_halts++;
    u->out_halted = false;
    for (;;) {
        slp_gsusb_usb_out_t *first = NULL;
        for (size_t i = 0; i < SLP_GSUSB_USB_OUT_XFERS; i++) {
            slp_gsusb_usb_out_t *x = &u->out[i];
            if (x->state == X_STALLED && (first == NULL || (int32_t)(x->seq - first->seq) < 0)) {
                first = x;
            }
        }
        if (first == NULL) {
            break;
        }
        u->stats.out_resubmits++;
        if (submit_out(u, first) != 0) {
            break;
        }
    }
    for (size_t i = 0; i < SLP_GSUSB_USB_OUT_XFERS; i++) {
        if (u->out[i].state == X_STALLED) {
            u->out[i].state = X_IDLE; // could not be resent: lost (echo timeout reports it)
        }
    }
    return u->gone ? SLP_GSUSB_IO_NO_DEVICE : SLP_GSUSB_IO_OK;
}

static bool op_out_stalled(void *ctx)
{
    slp_gsusb_usb_t *u = ctx;
    if (u->h != NULL && !u->gone) {
        handle_events_ms(u, 0);
    }
    return u->h != NULL && !u->gone && u->out_halted;
}

static const slp_gsusb_transport_ops_t usb_ops = {
    .control_out = op_control_out,
    .control_in = op_control_in,
    .bulk_out = op_bulk_out,
    .bulk_in = op_bulk_in,
    .clear_halt = op_clear_halt,
    .out_stalled = op_out_stalled,
};

slp_gsusb_transport_t slp_gsusb_usb_transport(slp_gsusb_usb_t *u)
{
    slp_gsusb_transport_t t = {&usb_ops, u};
    return t;
}

size_t slp_gsusb_usb_pollfds(slp_gsusb_usb_t *u, struct pollfd *fds, size_t cap)
{
    if (u == NULL || u->ctx == NULL || fds == NULL) {
        return 0;
    }
    const struct libusb_pollfd **p = libusb_get_pollfds(u->ctx);
    size_t n = 0;
    if (p == NULL) {
        return 0;
    }
    for (size_t i = 0; p[i] != NULL && n < cap; i++) {
        fds[n].fd = p[i]->fd;
        fds[n].events = p[i]->events;
        fds[n].revents = 0;
        n++;
    }
    libusb_free_pollfds(p);
    return n;
}

int slp_gsusb_usb_list(slp_gsusb_usb_t *u, char *buf, size_t cap)
{
    if (u == NULL || u->ctx == NULL || buf == NULL || cap == 0U) {
        return -1;
    }
    buf[0] = '\0';
    libusb_device **list = NULL;
    ssize_t n = libusb_get_device_list(u->ctx, &list);
    if (n < 0) {
        return -1;
    }
    int found = 0;
    size_t k = 0;
    for (ssize_t i = 0; i < n; i++) {
        struct libusb_device_descriptor dd;
        if (libusb_get_device_descriptor(list[i], &dd) != 0 ||
            !slp_gsusb_is_known_id(dd.idVendor, dd.idProduct)) {
            continue;
        }
        char where[32];
        port_name(list[i], where, sizeof where);
        int w = snprintf(buf + k, cap - k, "%04x:%04x at %s\n", (unsigned)dd.idVendor,
                         (unsigned)dd.idProduct, where);
        if (w > 0 && (size_t)w < cap - k) {
            k += (size_t)w;
        }
        found++;
    }
    libusb_free_device_list(list, 1);
    return found;
}
