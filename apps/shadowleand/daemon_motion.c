// SPDX-License-Identifier: MIT
// daemon_motion.c: VehicleMotion reader on SocketCAN (see daemon_motion.h).
#include "daemon_motion.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

static sl_err_t try_open(sld_motion_t *m, uint64_t now_us)
{
    m->next_open_us = now_us + SLD_MOTION_REOPEN_US;
    const int fd = socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
    if (fd < 0) {
        m->last_errno = errno;
        m->stats.failures++;
        return SL_ERR_PORT;
    }
    struct can_filter flt;
    if ((m->id_dbc & SL_CAN_DBC_EFF_BIT) != 0) {
        flt.can_id = (canid_t)((m->id_dbc & SL_CAN_EFF_MASK) | CAN_EFF_FLAG);
        flt.can_mask = CAN_EFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
    } else {
        flt.can_id = (canid_t)(m->id_dbc & SL_CAN_SFF_MASK);
        flt.can_mask = CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    struct sockaddr_can addr;
    memset(&addr, 0, sizeof addr);
    addr.can_family = AF_CAN;
    const unsigned idx = if_nametoindex(m->ifname);
    if (idx == 0 || setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, &flt, sizeof flt) != 0) {
        m->last_errno = idx == 0 ? ENODEV : errno;
        m->stats.failures++;
        close(fd);
        return SL_ERR_PORT;
    }
    addr.can_ifindex = (int)idx;
    if (bind(fd, (const struct sockaddr *)&addr, sizeof addr) != 0) {
        m->last_errno = errno;
        m->stats.failures++;
        close(fd);
        return SL_ERR_PORT;
    }
    m->fd = fd;
    m->stats.opens++;
    return SL_OK;
}

sl_err_t sld_motion_open(sld_motion_t *m, const char *ifname, uint32_t id_dbc, uint64_t now_us)
{
    memset(m, 0, sizeof *m);
    m->fd = -1;
    const size_t n = ifname != NULL ? strlen(ifname) : 0;
    if (n == 0 || n >= sizeof m->ifname) {
        return SL_ERR_ARG;
    }
    memcpy(m->ifname, ifname, n + 1);
    m->id_dbc = id_dbc;
    return try_open(m, now_us);
}

int sld_motion_fd(const sld_motion_t *m)
{
    return m->fd;
}

unsigned sld_motion_read(sld_motion_t *m, uint64_t now_us,
                         void (*on_frame)(void *ctx, const sl_can_frame_t *f), void *ctx)
{
    if (m->fd < 0) {
        if (m->ifname[0] == '\0' || now_us < m->next_open_us || try_open(m, now_us) != SL_OK) {
            return 0;
        }
    }
    unsigned got = 0;
    for (unsigned i = 0; i < SLD_MOTION_RX_BURST; i++) {
        struct can_frame cf;
        const ssize_t n = recv(m->fd, &cf, sizeof cf, 0);
        if (n < 0) {
            if (errno == EAGAIN || errno == EWOULDBLOCK || errno == EINTR) {
                break;
            }
            // Interface gone or down: close and reopen later.
            m->last_errno = errno;
            m->stats.failures++;
            close(m->fd);
            m->fd = -1;
            m->next_open_us = now_us + SLD_MOTION_REOPEN_US;
            break;
        }
        if ((size_t)n < sizeof cf) {
            continue; // CAN FD or short read: not ours
        }
        sl_can_frame_t f;
        memset(&f, 0, sizeof f);
        f.flags = (uint8_t)(((cf.can_id & CAN_EFF_FLAG) != 0 ? SL_CAN_FLAG_EFF : 0U) |
                            ((cf.can_id & CAN_RTR_FLAG) != 0 ? SL_CAN_FLAG_RTR : 0U) |
                            ((cf.can_id & CAN_ERR_FLAG) != 0 ? SL_CAN_FLAG_ERR : 0U));
        f.id = (cf.can_id & CAN_EFF_FLAG) != 0 ? (cf.can_id & CAN_EFF_MASK) : (cf.can_id & CAN_SFF_MASK);
        f.dlc = cf.can_dlc > 8 ? 8 : cf.can_dlc;
        memcpy(f.data, cf.data, f.dlc);
        m->stats.frames++;
        got++;
        on_frame(ctx, &f);
    }
    return got;
}

void sld_motion_close(sld_motion_t *m)
{
    if (m->fd >= 0) {
        close(m->fd);
    }
    m->fd = -1;
    m->ifname[0] = '\0';
}
