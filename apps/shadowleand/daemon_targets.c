// SPDX-License-Identifier: MIT
// daemon_targets.c: JSON-lines side file of targets and tracks (see daemon_targets.h).
#include "daemon_targets.h"

#include <inttypes.h>

int sld_targets_write_header(FILE *fp, const sl_board_t *b, const sl_pipeline_cfg_t *cfg)
{
    const int n = fprintf(
        fp,
        "{\"type\":\"header\",\"schema\":\"" SLD_TARGETS_SCHEMA "\""
        ",\"board\":\"%s\",\"azimuths\":%u,\"radar_yaw_cdeg\":%" PRId32
        ",\"confirm_hits\":%u,\"bin_size_um\":%" PRIu32 ",\"threshold\":%u,\"mask_frames\":%u"
        ",\"can_id_pole_lean\":%" PRIu32 ",\"can_id_lean_warning\":%" PRIu32
        ",\"can_id_status\":%" PRIu32 ",\"can_id_vehicle_motion\":%" PRIu32 "}\n",
        b->name, (unsigned)b->azimuths, b->radar_yaw_cdeg, (unsigned)cfg->confirm_hits,
        b->bin_size_um, (unsigned)cfg->threshold, (unsigned)cfg->mask_frames, b->can_id_pole_lean,
        b->can_id_lean_warning, b->can_id_status, b->can_id_vehicle_motion);
    return n < 0 ? -1 : 0;
}

// ,"model":{...},"targets":[ : the sensor model after the rotation.
static int write_model(FILE *fp, const sl_pipeline_rotation_t *r)
{
    const sl_response_t *m = r->model;
    int bad = 0;
    bad |= fprintf(fp, ",\"model\":{\"response\":\"%s\",\"peaks\":%" PRIu32
                       ",\"half_power_bins\":%.3f,\"floor_db\":[",
                   m->source == SL_RESPONSE_LEARNED      ? "learned"
                   : m->source == SL_RESPONSE_CALIBRATED ? "calibrated"
                                                         : "prior",
                   m->learn_n, sl_response_hpw_q8(m) / 256.0) < 0;
    for (uint16_t b = 0; b < r->bands; b++) {
        const int32_t f = sl_response_floor_lp(m, (uint32_t)b * SL_RESP_FLOOR_BAND);
        bad |= (f == INT32_MIN ? fprintf(fp, "%snull", b ? "," : "")
                               : fprintf(fp, "%s%.2f", b ? "," : "", f * 3.0103 / 256.0)) < 0;
    }
    bad |= fputs("],\"threshold\":[", fp) < 0;
    for (uint16_t b = 0; b < r->bands; b++) {
        bad |= fprintf(fp, "%s%u", b ? "," : "", (unsigned)r->threshold[b]) < 0;
    }
    bad |= fputs("]},\"targets\":[", fp) < 0;
    return bad ? -1 : 0;
}

int sld_targets_write_rotation(FILE *fp, const sl_pipeline_rotation_t *r)
{
    int bad = 0;
    bad |= fprintf(fp,
                   "{\"type\":\"rotation\",\"rotation\":%" PRIu32 ",\"now_us\":%" PRIu64
                   ",\"t_first_us\":%" PRIu64 ",\"t_last_us\":%" PRIu64
                   ",\"azimuths\":%u,\"valid\":%u,\"missing\":%u,\"end\":%u,\"frames_eff\":%u"
                   ",\"level\":%u,\"motion_valid\":%s,\"speed_mm_s\":%" PRId32
                   ",\"yaw_rate_cdeg_s\":%" PRId32,
                   r->rotation, r->now_us, r->t_first_us, r->t_last_us, (unsigned)r->azimuths,
                   (unsigned)r->valid, (unsigned)r->missing, (unsigned)r->end,
                   (unsigned)r->frames_eff, (unsigned)r->level,
                   r->motion_valid ? "true" : "false", r->speed_mm_s, r->yaw_rate_cdeg_s) < 0;
    bad |= write_model(fp, r) < 0;
    for (uint16_t i = 0; i < r->n_targets; i++) {
        const sl_target_t *t = &r->targets[i];
        bad |= fprintf(fp,
                       "%s{\"az\":%u,\"az_first\":%u,\"az_count\":%u,\"bin_first\":%u,"
                       "\"bin_last\":%u,\"r1_raw_um\":%" PRIu32 ",\"r2_raw_um\":%" PRIu32
                       ",\"r1_um\":%" PRIu32 ",\"r2_um\":%" PRIu32 ",\"radius_um\":%" PRIu32
                       ",\"alpha_cdeg\":%" PRId32 ",\"sigma_cdeg\":%u,\"flag\":%u,\"branch\":%u,"
                       "\"flags\":%u}",
                       i > 0 ? "," : "", (unsigned)t->az, (unsigned)t->az_first,
                       (unsigned)t->az_count, (unsigned)t->bin_first, (unsigned)t->bin_last,
                       t->r1_raw_um, t->r2_raw_um, t->r1_um, t->r2_um, t->radius_um, t->alpha_cdeg,
                       (unsigned)t->sigma_cdeg, (unsigned)t->incline_flag,
                       (unsigned)t->incline_branch, (unsigned)t->flags) < 0;
    }
    bad |= fputs("],\"tracks\":[", fp) < 0;
    int first = 1;
    for (uint16_t i = 0; r->tracks != NULL && i < r->n_track_slots; i++) {
        const sl_track_t *k = &r->tracks[i];
        if (!k->live) {
            continue;
        }
        bad |= fprintf(fp,
                       "%s{\"slot\":%u,\"id\":%u,\"az\":%u,\"r1_um\":%" PRIu32 ",\"r2_um\":%" PRIu32
                       ",\"alpha_cdeg\":%" PRId32 ",\"sigma_cdeg\":%u,\"hits\":%u,"
                       "\"valid_hits\":%u,\"level\":%u,\"last_flag\":%u,\"updated\":%u,"
                       "\"evidence\":%u,\"confirmed\":%u,\"last_slant\":%u}",
                       first ? "" : ",", (unsigned)i, (unsigned)k->id, (unsigned)k->az, k->r1_um,
                       k->r2_um, k->alpha_cdeg, (unsigned)k->sigma_cdeg, (unsigned)k->hits,
                       (unsigned)k->valid_hits, (unsigned)k->level, (unsigned)k->last_flag,
                       (unsigned)k->updated, (unsigned)k->evidence,
                       (unsigned)k->confirmed, (unsigned)k->last_slant) < 0;
        first = 0;
    }
    bad |= fputs("]}\n", fp) < 0;
    return bad ? -1 : 0;
}
