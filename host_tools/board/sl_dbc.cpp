// SPDX-License-Identifier: MIT
// sl_dbc.cpp: DBC generation from the core's CAN layout table (see sl_dbc.h).
#include "sl_dbc.h"

#include <cctype>
#include <cstdint>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "shadowlean/sl_can.h"

namespace sl {
namespace {

// Exact decimal text of num/den (den must divide a power of ten <= 10^9): "0.2", "-51.2".
std::string decimal(int64_t num, int64_t den)
{
    int digits = 0;
    int64_t p = 1;
    while (p % den != 0) {
        p *= 10;
        digits++;
        if (digits > 9) {
            throw std::invalid_argument("DBC factor denominator is not a divisor of 10^9");
        }
    }
    const int64_t scaled = num * (p / den); // value x 10^digits, exact
    const bool neg = scaled < 0;
    const uint64_t a = static_cast<uint64_t>(neg ? -scaled : scaled);
    std::string s = std::to_string(a / static_cast<uint64_t>(p));
    if (digits > 0) {
        std::string frac = std::to_string(a % static_cast<uint64_t>(p));
        frac.insert(0, static_cast<size_t>(digits) - frac.size(), '0');
        while (!frac.empty() && frac.back() == '0') {
            frac.pop_back();
        }
        if (!frac.empty()) {
            s += "." + frac;
        }
    }
    return neg ? "-" + s : s;
}

// DBC strings cannot hold a double quote.
std::string q(const std::string &s)
{
    std::string o;
    for (char c : s) {
        o += (c == '"') ? '\'' : c;
    }
    return "\"" + o + "\"";
}

std::string hex(unsigned v, int width)
{
    std::ostringstream o;
    o << "0x" << std::hex << std::uppercase;
    o.width(width);
    o.fill('0');
    o << v;
    return o.str();
}

const char *kSender = "SHADOWLEAN";
const char *kVehicle = "VEHICLE";

const char *kNetworkComment =
    "shadowlean: pole-lean estimation from a vehicle radar's chassis shadow. "
    "Classic CAN, DLC 8, all signals little-endian (Intel), physical = raw x factor. "
    "E2E protection on every message: AUTOSAR E2E Profile 11 with its default offsets, "
    "byte 0 = Crc, bits 8..11 = Counter, in mode 11C (nibble) bits 12..15 = the Data ID's "
    "bits 8..11. Each message's 16-bit Data ID is its attribute SlE2EDataId (not "
    "transmitted) and its mode the attribute SlE2EMode (Both = 11A, Nibble = 11C). "
    "Crc = CRC-8 poly 0x1D, start value 0x00, not reflected, no final XOR, over the Data "
    "ID's low byte, then its high byte (11A) or 0x00 (11C), then data bytes 1..7. Counter "
    "counts 0..14 per message and wraps to 0 (modulo 15); 15 is never sent and is an "
    "error. A Profile 11 receiver classifies a counter step of 1 as OK, 2..MaxDeltaCounter "
    "as OK_SOME_LOST, 0 as REPEATED, larger as WRONG_SEQUENCE. Vectors: 8 zero bytes, Data "
    "ID 0x123, counter 0: Crc 0xCC (11A), 0x2A with byte 1 = 0x10 (11C). Worked example: "
    "Status (Data ID 0x0053, 11A) with Counter 0, LinkState 3, Rotations 2 has bytes 1..7 "
    "= 30 02 00 00 00 00 00; CRC input 53 00 30 02 00 00 00 00 00 gives 0x93; frame = 93 30 "
    "02 00 00 00 00 00. "
    "Out-of-range values are clamped to the signal range and flagged (Clamped / Saturated "
    "bit), never wrapped; azimuths are reduced modulo 360 deg. Reserved bits are 0.";

const std::map<std::string, std::string> kMessageComments = {
    {"PoleLean",
     "One frame per confirmed target and radar rotation (GenMsgSendType CyclicIfActive): the in-plane lean of a slender object "
     "(pole, post, trunk) inside the vehicle's radar shadow. Lean and LeanSigma are "
     "meaningful only when Quality is VALID or FILTERED."},
    {"LeanWarning",
     "Once per rotation: the warning level and the most severe target (largest lean "
     "towards the vehicle). HasTarget = 0: no target; the target fields are 0."},
    {"Status", "Module health: once per radar rotation while data arrives (GenMsgCycleTime, "
               "250 ms at 4 Hz), every SlIdleCycleTime (1 s, the daemon's status_period_ms) "
               "without data. Counters are totals since start and stop at their maximum "
               "(Saturated = 1)."},
    {"VehicleMotion", "Input from the vehicle for the motion-aware masks: speed and yaw "
                      "rate with E2E protection. The module's Profile 11 check uses OK and "
                      "OK_SOME_LOST frames (counter step up to the board's max delta counter), "
                      "counts REPEATED, WRONG_SEQUENCE and ERROR frames (Health bit MOTION_E2E) "
                      "and never uses them, nor the first frame after a start or a 500 ms gap."},
    {"PoleTilt",
     "While driving (a motion input is present): one frame per confirmed target and radar "
     "rotation that has an observation history (GenMsgSendType CyclicIfActive): the pole's "
     "3D tilt fitted from its in-plane leans over the drive-by. The values are meaningful "
     "only when Quality is FITTED, AMBIGUOUS or MIRROR. AMBIGUOUS: the observations cannot "
     "tell the pole from its mirror image; the frame carries the better-fitting reading and "
     "is followed in the same rotation by a frame of the same TargetId with Quality MIRROR "
     "carrying the other one: the pole is one of the two."},
    {"GroundPlane",
     "Once per rotation while the module's ground estimation is on: the vehicle's attitude "
     "over the ground from where the ground return starts around the vehicle (the plane "
     "through the ring of ground points 3-6 m out, filtered over rotations). Pitch and Roll "
     "are relative to that ground, not to gravity. Quality NONE: no plane this rotation, "
     "every value 0."},
    {"GroundHazard",
     "One frame per sector of the ring whose ground departs from the plane (DROP: lower, "
     "STEP: higher, beyond the board's thresholds and 4 sigma, confirmed over rotations "
     "with hysteresis), every rotation while it holds (GenMsgSendType CyclicIfActive), "
     "right after that rotation's GroundPlane. No frame: no confirmed hazard."},
    {"Health", "Sent right after every Status: why the output may be degraded or blind. "
               "Any Fault bit set means do not trust an absent warning. A bit is set when "
               "its condition held since the previous Health frame or still holds."},
};

// key "Message.Signal"
const std::map<std::string, std::string> kSignalComments = {
    {"*.Crc", "E2E Profile 11 CRC-8 (poly 0x1D, start 0x00, no XOR) over [Data ID low byte, "
              "high byte or 0x00, bytes 1..7]; see the network comment."},
    {"*.Counter", "E2E counter 0..14 per message, modulo 15; 15 is invalid."},
    {"PoleLean.Quality", "Estimate quality."},
    {"PoleLean.Clamped", "1: at least one value of this frame hit its signal range limit "
                         "and is sent as that limit (a bound, not a measurement)."},
    {"PoleLean.TargetId", "Tracker id of the target, stable over rotations, 0..15."},
    {"PoleLean.Azimuth", "Direction of the target, clockwise from the vehicle's forward "
                         "axis seen from above."},
    {"PoleLean.Lean", "In-plane lean from vertical in the target's azimuth plane; positive: "
                      "the top leans towards the vehicle. Clamped to +-51.1 deg here; "
                      "LeanWarning carries +-102 deg."},
    {"PoleLean.LeanSigma", "1-sigma uncertainty of Lean; 6.2 with Clamped = 1 means >= 6.2."},
    {"PoleLean.RangeInner", "Inner bound r1 of the target's radar return (slant range)."},
    {"PoleLean.RangeOuter", "Outer bound r2 of the target's radar return (slant range)."},
    {"LeanWarning.Level", "Warning level with hysteresis, from the board's caution/danger "
                          "lean thresholds."},
    {"LeanWarning.Clamped", "1: at least one value hit its range limit."},
    {"LeanWarning.HasTarget", "1: the target fields describe the most severe target."},
    {"LeanWarning.TargetId", "Tracker id of the most severe target (as in PoleLean)."},
    {"LeanWarning.Azimuth", "Direction, clockwise from vehicle forward."},
    {"LeanWarning.Lean", "Lean of the most severe target; positive: top towards the vehicle."},
    {"LeanWarning.Range", "Inner bound r1 of the most severe target."},
    {"LeanWarning.LeanSigma", "1-sigma uncertainty of Lean."},
    {"LeanWarning.Quality", "Quality of the most severe target's estimate."},
    {"Status.LinkState", "State of the radar TCP link."},
    {"Status.Saturated", "1: a counter of this frame is stuck at its maximum."},
    {"Status.Rotations", "Radar rotations processed since start (saturating)."},
    {"Status.AzimuthsMissing", "Azimuths lost in gaps of the radar stream (saturating)."},
    {"Status.DecoderResyncs", "Radar stream decoder resynchronisations (saturating)."},
    {"Status.CanDropped", "CAN frames the module's CAN outputs dropped (saturating)."},
    {"Health.Fault",
     "Bitfield; the value table names each bit's value: 1 CONFIG_MISMATCH (radar azimuths or "
     "encoder size differ from the board: every row refused), 2 NO_USABLE_ROWS (link up, no "
     "usable FFT row), 4 MALFORMED_DATA (malformed messages, resyncs, empty rows, encoder "
     "values out of range), 8 LINK_FLAPPING (3 reconnects within 30 s), 16 CAN_OUTPUT_ERRORS "
     "(frames dropped by the CAN outputs), 32 RANGE_RESOLUTION_MISMATCH (radar bin size "
     "differs from the board's by more than 1 %), 64 AZIMUTH_DISORDER (azimuths stepped back "
     "beyond the reorder window), 128 CAN_RATE_LIMITED (frames withheld by the output "
     "ceiling), 256 TARGET_SLOTS_OVERFLOW (more candidates than target slots), 512 "
     "THETA_DRIFT (the live theta differs from the calibration's), 1024 MOTION_E2E "
     "(VehicleMotion frames rejected by the E2E check: ERROR, REPEATED, WRONG_SEQUENCE). "
     "Bits 11..15 reserved (0)."},
    {"Health.Reconnects", "Radar link reconnects since start (saturating at 255)."},
    {"Health.CandidatesDropped", "Detection candidates dropped for lack of target slots since "
                                 "start (saturating at 4095)."},
    {"PoleTilt.Quality", "Fit quality: FITTED, AMBIGUOUS (the mirror hypothesis fits as well: "
                         "this is one of two readings), INSUFFICIENT_MOTION (bearings do not "
                         "spread), TOO_FEW (observations), INCONSISTENT (residuals far above "
                         "the sigmas), MIRROR (the other reading of the AMBIGUOUS frame just "
                         "sent for this TargetId)."},
    {"PoleTilt.Clamped", "1: at least one value hit its range limit."},
    {"PoleTilt.TargetId", "Tracker id of the target (as in PoleLean)."},
    {"PoleTilt.Tilt", "Tilt of the pole from vertical (psi)."},
    {"PoleTilt.TiltDirection", "Direction the top leans towards, in the vehicle frame at "
                               "this frame's time: counter-clockwise from the vehicle's "
                               "forward axis seen from above, 0..359."},
    {"PoleTilt.TiltSigma", "1-sigma uncertainty of Tilt."},
    {"PoleTilt.DirectionSigma", "1-sigma uncertainty of TiltDirection (63: too small a tilt "
                                "to orient)."},
    {"PoleTilt.BaseX", "Pole base on the ground, vehicle frame at this frame's time: "
                       "forward of the vehicle origin."},
    {"PoleTilt.BaseY", "Pole base on the ground: left of the vehicle origin."},
    {"GroundPlane.Quality", "NONE: no plane (every value 0); COARSE: a plane whose sigmas "
                            "exceed the module's good limits; GOOD: within them."},
    {"GroundPlane.Clamped", "1: at least one value hit its range limit (a sigma at its "
                            "maximum means at least that)."},
    {"GroundPlane.Height", "The radar's height above the ground plane, perpendicular to it."},
    {"GroundPlane.Pitch", "Pitch of the vehicle over the ground plane; positive: nose down "
                          "(ISO 8855)."},
    {"GroundPlane.Roll", "Roll of the vehicle over the ground plane; positive: right side "
                         "down (ISO 8855)."},
    {"GroundPlane.HeightSigma", "1-sigma uncertainty of Height."},
    {"GroundPlane.PitchSigma", "1-sigma uncertainty of Pitch."},
    {"GroundPlane.RollSigma", "1-sigma uncertainty of Roll."},
    {"GroundHazard.Kind", "DROP: the ground is lower than the plane (a ditch, a drop-off, a "
                          "dock edge); STEP: higher (a kerb, a bank, a wall at the edge)."},
    {"GroundHazard.Clamped", "1: at least one value hit its range limit."},
    {"GroundHazard.Sector", "Sector of the ring (equal shares of the rotation), stable over "
                            "rotations: the hazard's identity."},
    {"GroundHazard.Azimuth", "The sector's centre, clockwise from the vehicle's forward axis "
                             "seen from above."},
    {"GroundHazard.HeightDiff", "The ground's height relative to the plane at the sector's "
                                "edge: negative lower (DROP), positive higher (STEP)."},
    {"GroundHazard.Distance", "Horizontal distance from the radar to where the ground at the "
                              "plane's level ends along the sector, moved back by the "
                              "vehicle's forward travel while the hazard holds."},
    {"GroundHazard.Sigma", "1-sigma uncertainty of HeightDiff."},
    {"VehicleMotion.SpeedValid", "1: Speed is valid."},
    {"VehicleMotion.YawRateValid", "1: YawRate is valid."},
    {"VehicleMotion.Speed", "Vehicle speed over ground; positive forward."},
    {"VehicleMotion.YawRate", "Yaw rate; positive counter-clockwise seen from above (ISO 8855)."},
};

std::string signal_comment(const std::string &msg, const std::string &sig)
{
    auto it = kSignalComments.find(msg + "." + sig);
    if (it == kSignalComments.end()) {
        it = kSignalComments.find("*." + sig);
    }
    return it == kSignalComments.end() ? std::string() : it->second;
}

// The layout of one message as a text table, for its CM_ comment.
std::string layout_table(const sl_can_message_desc_t &m)
{
    std::ostringstream o;
    o << "Layout (start|length, Intel; s = signed; factor; range):";
    for (unsigned i = 0; i < m.n_signals; i++) {
        const sl_can_signal_desc_t &s = m.signals[i];
        o << (i == 0 ? " " : "; ") << s.name << " " << unsigned(s.start) << "|"
          << unsigned(s.length) << (s.is_signed ? " s" : "") << " x"
          << decimal(s.factor_num, s.factor_den) << " ["
          << decimal(int64_t(s.raw_min) * s.factor_num, s.factor_den) << ".."
          << decimal(int64_t(s.raw_max) * s.factor_num, s.factor_den) << "]"
          << (s.unit[0] != '\0' ? std::string(" ") + s.unit : std::string());
    }
    o << ".";
    return o.str();
}

} // namespace

sl_can_ids_t can_ids(const BoardSpec &b)
{
    sl_can_ids_t ids{};
    const unsigned id[SL_CAN_MSG_COUNT] = {b.can_id_pole_lean,      b.can_id_lean_warning,
                                           b.can_id_status,         b.can_id_vehicle_motion,
                                           b.can_id_health,         b.can_id_pole_tilt,
                                           b.can_id_ground_plane,   b.can_id_ground_hazard};
    for (unsigned m = 0; m < SL_CAN_MSG_COUNT; m++) {
        ids.id[m] = id[m];
        ids.e2e[m].data_id = static_cast<uint16_t>(b.can_data_id[m]);
        ids.e2e[m].mode = static_cast<uint8_t>(b.can_data_id_mode[m]);
    }
    return ids;
}

namespace {

std::string db_name(const std::string &board)
{
    std::string n = "shadowlean_";
    for (char c : board) {
        n += (std::isalnum(static_cast<unsigned char>(c)) != 0) ? c : '_';
    }
    return n;
}

} // namespace

std::string make_dbc(const BoardSpec &b)
{
    // Ids: validated the way the core's sl_can_tx_init() does.
    const sl_can_ids_t ids = can_ids(b);
    sl_can_tx_t tx;
    if (sl_can_tx_init(&tx, &ids) != SL_OK) {
        throw std::invalid_argument("board " + b.name +
                                    ": CAN ids must be distinct 11-bit ids (or 29-bit ids with "
                                    "bit 31 set), Data IDs distinct, mode 11C only on Health "
                                    "with a Data ID <= 0x0FFF");
    }
    if (b.max_targets > static_cast<int>(SL_CAN_TARGET_ID_MAX) + 1) {
        throw std::invalid_argument("board " + b.name + ": max_targets " +
                                    std::to_string(b.max_targets) +
                                    " exceeds the 16 ids of PoleLean.TargetId");
    }

    std::ostringstream o;
    o << "VERSION \"shadowlean " << b.name << " (" << kDbcGeneratorVersion << ")\"\n\n\n";
    o << "NS_ :\n";
    for (const char *ns : {"NS_DESC_", "CM_", "BA_DEF_", "BA_", "VAL_", "CAT_DEF_", "CAT_",
                           "FILTER", "BA_DEF_DEF_", "EV_DATA_", "ENVVAR_DATA_", "SGTYPE_",
                           "SGTYPE_VAL_", "BA_DEF_SGTYPE_", "BA_SGTYPE_", "SIG_TYPE_REF_",
                           "VAL_TABLE_", "SIG_GROUP_", "SIG_VALTYPE_", "SIGTYPE_VALTYPE_",
                           "BO_TX_BU_", "BA_DEF_REL_", "BA_REL_", "BA_DEF_DEF_REL_",
                           "BU_SG_REL_", "BU_EV_REL_", "BU_BO_REL_", "SG_MUL_VAL_"}) {
        o << "\t" << ns << "\n";
    }
    o << "\nBS_:\n\n";
    o << "BU_: " << kSender << " " << kVehicle << "\n\n\n";

    for (unsigned mi = 0; mi < SL_CAN_MSG_COUNT; mi++) {
        const sl_can_message_desc_t &m = *sl_can_layout(static_cast<sl_can_msg_t>(mi));
        const char *tx_node = m.to_shadowlean ? kVehicle : kSender;
        const char *rx_node = m.to_shadowlean ? kSender : kVehicle;
        o << "BO_ " << ids.id[mi] << " " << m.name << ": 8 " << tx_node << "\n";
        for (unsigned si = 0; si < m.n_signals; si++) {
            const sl_can_signal_desc_t &s = m.signals[si];
            o << " SG_ " << s.name << " : " << unsigned(s.start) << "|" << unsigned(s.length)
              << "@1" << (s.is_signed ? "-" : "+") << " ("
              << decimal(s.factor_num, s.factor_den) << ",0) ["
              << decimal(int64_t(s.raw_min) * s.factor_num, s.factor_den) << "|"
              << decimal(int64_t(s.raw_max) * s.factor_num, s.factor_den) << "] "
              << q(s.unit) << " " << rx_node << "\n";
        }
        if (ids.e2e[mi].mode == SL_CAN_E2E_MODE_NIBBLE) {
            // Profile 11C: the Data ID's bits 8..11 in frame bits 12..15 (free in this layout).
            o << " SG_ DataIdNibble : 12|4@1+ (1,0) [0|15] \"\" " << rx_node << "\n";
        }
        o << "\n";
    }
    o << "\n";

    o << "CM_ " << q(kNetworkComment) << ";\n";
    o << "CM_ BU_ " << kSender << " "
      << q("shadowlean module (radar companion computer), board " + b.name + ": " +
           b.description)
      << ";\n";
    o << "CM_ BU_ " << kVehicle << " "
      << q("The vehicle: consumes PoleLean, LeanWarning, Status, Health, PoleTilt, "
             "GroundPlane, GroundHazard; sends VehicleMotion.")
      << ";\n";
    for (unsigned mi = 0; mi < SL_CAN_MSG_COUNT; mi++) {
        const sl_can_message_desc_t &m = *sl_can_layout(static_cast<sl_can_msg_t>(mi));
        std::ostringstream e2e;
        e2e << " E2E Profile 11: Data ID " << hex(ids.e2e[mi].data_id, 4) << ", mode "
            << (ids.e2e[mi].mode == SL_CAN_E2E_MODE_NIBBLE ? "11C (nibble)" : "11A (both)") << ".";
        o << "CM_ BO_ " << ids.id[mi] << " "
          << q(kMessageComments.at(m.name) + " " + layout_table(m) + e2e.str()) << ";\n";
        for (unsigned si = 0; si < m.n_signals; si++) {
            const std::string c = signal_comment(m.name, m.signals[si].name);
            if (!c.empty()) {
                o << "CM_ SG_ " << ids.id[mi] << " " << m.signals[si].name << " " << q(c) << ";\n";
            }
        }
        if (ids.e2e[mi].mode == SL_CAN_E2E_MODE_NIBBLE) {
            o << "CM_ SG_ " << ids.id[mi] << " DataIdNibble "
              << q("E2E Profile 11C: bits 8..11 of the Data ID (always " +
                   std::to_string((ids.e2e[mi].data_id >> 8) & 0x0FU) + ").")
              << ";\n";
        }
    }

    o << "BA_DEF_  \"BusType\" STRING ;\n";
    o << "BA_DEF_  \"DBName\" STRING ;\n";
    o << "BA_DEF_  \"Baudrate\" INT 10000 1000000;\n";
    o << "BA_DEF_ BO_  \"GenMsgCycleTime\" INT 0 65535;\n";
    // Vector's value table: the index is what the layout's send_type holds.
    o << "BA_DEF_ BO_  \"GenMsgSendType\" ENUM  \"Cyclic\",\"Spontaneous\",\"CyclicIfActive\","
         "\"SpontaneousWithDelay\",\"CyclicAndSpontaneous\",\"CyclicAndSpontaneousWithDelay\","
         "\"SpontaneousWithRepetition\",\"CyclicIfActiveAndSpontaneous\","
         "\"CyclicIfActiveAndSpontaneousWithDelay\",\"NoMsgSendType\";\n";
    o << "BA_DEF_ BO_  \"SlIdleCycleTime\" INT 0 65535;\n";
    o << "BA_DEF_ BO_  \"SlE2EDataId\" INT 0 65535;\n";
    o << "BA_DEF_ BO_  \"SlE2EMode\" ENUM  \"Both\",\"Nibble\";\n";
    o << "BA_DEF_ BO_  \"VFrameFormat\" ENUM  \"StandardCAN\",\"ExtendedCAN\",\"reserved\","
         "\"J1939PG\";\n";
    o << "BA_DEF_DEF_  \"BusType\" \"CAN\";\n";
    o << "BA_DEF_DEF_  \"DBName\" \"\";\n";
    o << "BA_DEF_DEF_  \"Baudrate\" 500000;\n";
    o << "BA_DEF_DEF_  \"GenMsgCycleTime\" 0;\n";
    o << "BA_DEF_DEF_  \"GenMsgSendType\" \"NoMsgSendType\";\n";
    o << "BA_DEF_DEF_  \"SlIdleCycleTime\" 0;\n";
    o << "BA_DEF_DEF_  \"SlE2EDataId\" 0;\n";
    o << "BA_DEF_DEF_  \"SlE2EMode\" \"Both\";\n";
    o << "BA_DEF_DEF_  \"VFrameFormat\" \"StandardCAN\";\n";
    o << "BA_ \"BusType\" \"CAN\";\n";
    o << "BA_ \"DBName\" " << q(db_name(b.name)) << ";\n";
    o << "BA_ \"Baudrate\" " << b.can_bitrate << ";\n";
    for (unsigned mi = 0; mi < SL_CAN_MSG_COUNT; mi++) {
        const sl_can_message_desc_t &m = *sl_can_layout(static_cast<sl_can_msg_t>(mi));
        o << "BA_ \"GenMsgCycleTime\" BO_ " << ids.id[mi] << " " << m.cycle_ms << ";\n";
        o << "BA_ \"GenMsgSendType\" BO_ " << ids.id[mi] << " " << unsigned(m.send_type) << ";\n";
        if (m.idle_cycle_ms != 0) {
            o << "BA_ \"SlIdleCycleTime\" BO_ " << ids.id[mi] << " " << m.idle_cycle_ms << ";\n";
        }
        o << "BA_ \"SlE2EDataId\" BO_ " << ids.id[mi] << " " << unsigned(ids.e2e[mi].data_id)
          << ";\n";
        o << "BA_ \"SlE2EMode\" BO_ " << ids.id[mi] << " " << unsigned(ids.e2e[mi].mode) << ";\n";
        if ((ids.id[mi] & SL_CAN_DBC_EFF_BIT) != 0U) {
            o << "BA_ \"VFrameFormat\" BO_ " << ids.id[mi] << " 1;\n";
        }
    }

    for (unsigned mi = 0; mi < SL_CAN_MSG_COUNT; mi++) {
        const sl_can_message_desc_t &m = *sl_can_layout(static_cast<sl_can_msg_t>(mi));
        for (unsigned si = 0; si < m.n_signals; si++) {
            const sl_can_signal_desc_t &s = m.signals[si];
            if (s.values == nullptr) {
                continue;
            }
            o << "VAL_ " << ids.id[mi] << " " << s.name;
            for (unsigned k = s.n_values; k-- > 0;) {
                o << " " << s.values[k].value << " " << q(s.values[k].name);
            }
            o << " ;\n";
        }
    }
    o << "\n";
    return o.str();
}

} // namespace sl
