-- SPDX-License-Identifier: MIT
-- colossus.lua: Wireshark / tshark dissector for the Navtech Colossus TCP protocol
-- (CTS350-X and related radars; shadowlean project, packaging/wireshark).
--
-- Install: copy to ~/.local/lib/wireshark/plugins/ (or the system plugin folder,
-- /usr/lib/x86_64-linux-gnu/wireshark/plugins/ on Debian), or load it for one run:
--     tshark -X lua_script:colossus.lua -r capture.pcapng -Y colossus
--     wireshark -X lua_script:colossus.lua capture.pcapng
--
-- Wire format (docs/PROTOCOL.md in the shadowlean repository, and the core's
-- include/shadowlean/sl_proto.h which is the source of truth for the values below):
--   header, 22 bytes: signature 00 01 03 03 07 07 0F 0F 1F 1F 3F 3F 7F 7F FE FE,
--   version (u8, 1), message id (u8), payload size (u32 big-endian), then the payload.
--   Configuration (10): azimuths u16 BE, bin size u16 BE (0.1 mm), range bins u16 BE,
--     encoder size u16 BE, rotation u16 BE (mHz), packet rate u16 BE, range gain f32 BE,
--     range offset f32 BE (m), then a ConfigurationData protobuf (fields 9 datawidth and
--     10 rangeresolutionmetres decoded here).
--   FFT data (30 8-bit, 31 16-bit little-endian bins): data offset u16 BE (14), sweep counter
--     u16 BE, azimuth u16 BE (encoder ticks), seconds u32 LITTLE-endian, nanoseconds u32
--     LITTLE-endian, bins from the data offset.
--   Navigation data (123): azimuth u16 BE, seconds u32 BE, split seconds u32 BE, then
--     6-byte peaks (range u32 BE in micrometres, power u16 BE in dB x 10).
-- Messages span TCP segments; they are reassembled (pinfo.desegment_*). A stream that does
-- not start at a signature (a capture started mid-session) is resynchronised: the bytes up
-- to the next signature are shown as "junk" with an expert warning, never misparsed.

local p = Proto("colossus", "Navtech Colossus radar protocol")

local SIGNATURE = "\x00\x01\x03\x03\x07\x07\x0F\x0F\x1F\x1F\x3F\x3F\x7F\x7F\xFE\xFE"
local HEADER_BYTES = 22
local MAX_PAYLOAD = 1048576 -- the decoder's limit: larger sizes are treated as corrupt

local msg_names = {
    [1] = "Keep Alive", [10] = "Configuration", [20] = "Configuration Request",
    [21] = "Start FFT Data", [22] = "Stop FFT Data", [23] = "Start Health Msgs",
    [24] = "Stop Health Msgs", [25] = "Recalibrate RF Health", [28] = "Transmit On",
    [29] = "Transmit Off", [30] = "FFT Data", [31] = "High-Precision FFT Data",
    [40] = "Health", [50] = "Contour Update", [51] = "Sector Blanking Update",
    [76] = "System Restart", [120] = "Start Nav Data", [121] = "Stop Nav Data",
    [122] = "Set Nav Threshold", [123] = "Navigation Data",
    [124] = "Set Nav Range Offset and Gain", [140] = "Start Non-Contour FFT Data",
}

local f = {
    signature   = ProtoField.bytes("colossus.signature", "Signature"),
    version     = ProtoField.uint8("colossus.version", "Version"),
    id          = ProtoField.uint8("colossus.id", "Message id", base.DEC, msg_names),
    payload_len = ProtoField.uint32("colossus.payload_len", "Payload size"),
    junk        = ProtoField.bytes("colossus.junk", "Bytes before a signature (resync)"),
    junk_len    = ProtoField.uint32("colossus.junk_len", "Bytes skipped (resync)"),
    -- Configuration (10)
    cfg_azimuths = ProtoField.uint16("colossus.cfg.azimuths", "Azimuths per rotation"),
    cfg_bin_size = ProtoField.uint16("colossus.cfg.bin_size", "Bin size (0.1 mm)"),
    cfg_range_bins = ProtoField.uint16("colossus.cfg.range_bins", "Range in bins"),
    cfg_encoder = ProtoField.uint16("colossus.cfg.encoder_size", "Encoder size (ticks)"),
    cfg_rotation = ProtoField.uint16("colossus.cfg.rotation_mhz", "Rotation speed (mHz)"),
    cfg_packet_rate = ProtoField.uint16("colossus.cfg.packet_rate", "Packet rate (1/s)"),
    cfg_gain = ProtoField.float("colossus.cfg.range_gain", "Range gain"),
    cfg_offset = ProtoField.float("colossus.cfg.range_offset", "Range offset (m)"),
    cfg_protobuf = ProtoField.bytes("colossus.cfg.protobuf", "ConfigurationData protobuf"),
    cfg_datawidth = ProtoField.int32("colossus.cfg.datawidth", "Data width (bytes per bin)"),
    cfg_range_res = ProtoField.float("colossus.cfg.range_resolution_m", "Range resolution (m)"),
    -- FFT data (30, 31)
    fft_offset  = ProtoField.uint16("colossus.fft.offset", "FFT data offset"),
    fft_sweep   = ProtoField.uint16("colossus.fft.sweep", "Sweep counter"),
    fft_azimuth = ProtoField.uint16("colossus.fft.azimuth", "Azimuth (encoder ticks)"),
    fft_angle   = ProtoField.double("colossus.fft.angle_deg", "Azimuth (deg)"),
    fft_seconds = ProtoField.uint32("colossus.fft.seconds", "Seconds"),
    fft_nanos   = ProtoField.uint32("colossus.fft.nanoseconds", "Split seconds (ns)"),
    fft_time    = ProtoField.absolute_time("colossus.fft.time", "Time", base.UTC),
    fft_bins    = ProtoField.uint32("colossus.fft.bins", "Bins"),
    fft_max     = ProtoField.uint16("colossus.fft.max", "Largest bin value"),
    fft_data    = ProtoField.bytes("colossus.fft.data", "Bin data"),
    -- Navigation data (123)
    nav_azimuth = ProtoField.uint16("colossus.nav.azimuth", "Azimuth (encoder ticks)"),
    nav_seconds = ProtoField.uint32("colossus.nav.seconds", "Seconds"),
    nav_split   = ProtoField.uint32("colossus.nav.split", "Split seconds"),
    nav_peaks   = ProtoField.uint32("colossus.nav.peaks", "Peaks"),
    nav_range   = ProtoField.uint32("colossus.nav.range_um", "Peak range (um)"),
    nav_power   = ProtoField.uint16("colossus.nav.power", "Peak power (dB x 10)"),
    payload     = ProtoField.bytes("colossus.payload", "Payload"),
}
p.fields = f

local e_bad_version = ProtoExpert.new("colossus.bad_version", "Version is not 1",
    expert.group.MALFORMED, expert.severity.ERROR)
local e_oversize = ProtoExpert.new("colossus.oversize", "Payload size above 1 MiB (corrupt header)",
    expert.group.MALFORMED, expert.severity.ERROR)
local e_junk = ProtoExpert.new("colossus.junk", "Bytes that are not a message (resynchronised)",
    expert.group.MALFORMED, expert.severity.WARN)
local e_short = ProtoExpert.new("colossus.short", "Payload shorter than the message requires",
    expert.group.MALFORMED, expert.severity.ERROR)
p.experts = { e_bad_version, e_oversize, e_junk, e_short }

p.prefs.port = Pref.uint("TCP port", 6317, "Radar TCP port (IANA-assigned 6317)")
p.prefs.encoder_size = Pref.uint("Encoder size", 5600,
    "Encoder ticks per revolution, used for the azimuth angle until a Configuration is seen")

-- Encoder size learnt from the last Configuration seen in this capture (first pass order).
local learnt_encoder = nil

-- Returns the offset of the next signature at or after `from` in tvb, or nil.
local function find_signature(tvb, from)
    local n = tvb:len()
    local raw = tvb:raw(from, n - from)
    local s = string.find(raw, SIGNATURE, 1, true)
    if s == nil then return nil end
    return from + s - 1
end

-- Minimal protobuf walk for the two fields the module uses (9 varint, 10 fixed32 float).
local function dissect_protobuf(tvb, tree)
    local pos, n = 0, tvb:len()
    while pos < n do
        local key, shift = 0, 0
        repeat
            if pos >= n then return end
            local b = tvb(pos, 1):uint(); pos = pos + 1
            key = key + (b % 128) * (2 ^ shift); shift = shift + 7
        until b < 128 or shift > 63
        local field, wt = math.floor(key / 8), key % 8
        if wt == 0 then
            local start, v, sh = pos, 0, 0
            repeat
                if pos >= n then return end
                local b = tvb(pos, 1):uint(); pos = pos + 1
                v = v + (b % 128) * (2 ^ sh); sh = sh + 7
            until b < 128 or sh > 63
            if field == 9 then tree:add(f.cfg_datawidth, tvb(start, pos - start), v) end
        elseif wt == 5 then
            if pos + 4 > n then return end
            if field == 10 then tree:add_le(f.cfg_range_res, tvb(pos, 4)) end
            pos = pos + 4
        elseif wt == 1 then
            pos = pos + 8
        elseif wt == 2 then
            local len, sh = 0, 0
            repeat
                if pos >= n then return end
                local b = tvb(pos, 1):uint(); pos = pos + 1
                len = len + (b % 128) * (2 ^ sh); sh = sh + 7
            until b < 128 or sh > 63
            pos = pos + len
        else
            return -- groups or garbage: stop quietly, the bytes stay visible as protobuf
        end
    end
end

local function dissect_payload(id, tvb, tree, pinfo)
    local n = tvb:len()
    if id == 10 then
        if n < 20 then tree:add_proto_expert_info(e_short); return "Configuration (short)" end
        tree:add(f.cfg_azimuths, tvb(0, 2))
        tree:add(f.cfg_bin_size, tvb(2, 2))
        tree:add(f.cfg_range_bins, tvb(4, 2))
        tree:add(f.cfg_encoder, tvb(6, 2))
        tree:add(f.cfg_rotation, tvb(8, 2))
        tree:add(f.cfg_packet_rate, tvb(10, 2))
        tree:add(f.cfg_gain, tvb(12, 4))
        tree:add(f.cfg_offset, tvb(16, 4))
        local enc = tvb(6, 2):uint()
        if enc > 0 then learnt_encoder = enc end
        if n > 20 then
            local pb = tree:add(f.cfg_protobuf, tvb(20, n - 20))
            dissect_protobuf(tvb(20, n - 20):tvb(), pb)
        end
        return string.format("Configuration az=%d bin=%.4fm bins=%d enc=%d",
            tvb(0, 2):uint(), tvb(2, 2):uint() / 10000.0, tvb(4, 2):uint(), enc)
    elseif id == 30 or id == 31 then
        if n < 14 then tree:add_proto_expert_info(e_short); return "FFT (short)" end
        local off = tvb(0, 2):uint()
        tree:add(f.fft_offset, tvb(0, 2))
        tree:add(f.fft_sweep, tvb(2, 2))
        tree:add(f.fft_azimuth, tvb(4, 2))
        local az = tvb(4, 2):uint()
        local enc = learnt_encoder or p.prefs.encoder_size
        if enc > 0 then tree:add(f.fft_angle, tvb(4, 2), az * 360.0 / enc) end
        tree:add_le(f.fft_seconds, tvb(6, 4))
        tree:add_le(f.fft_nanos, tvb(10, 4))
        local secs, ns = tvb(6, 4):le_uint(), tvb(10, 4):le_uint()
        tree:add(f.fft_time, tvb(6, 8), NSTime.new(secs, ns))
        if off < 14 or off > n then
            tree:add_proto_expert_info(e_short)
            return string.format("FFT az=%d (bad data offset %d)", az, off)
        end
        local width = (id == 31) and 2 or 1
        local bins = math.floor((n - off) / width)
        tree:add(f.fft_bins, tvb(0, 0), bins)
        if bins > 0 then
            local data = tvb(off, n - off)
            local maxv = 0
            if width == 1 then
                local raw = data:raw()
                for i = 1, #raw do
                    local v = string.byte(raw, i)
                    if v > maxv then maxv = v end
                end
            else
                for i = 0, bins - 1 do
                    local v = data(2 * i, 2):le_uint()
                    if v > maxv then maxv = v end
                end
            end
            tree:add(f.fft_max, data, maxv)
            tree:add(f.fft_data, data)
        end
        return string.format("%s sweep=%d az=%d bins=%d", id == 31 and "FFT16" or "FFT8",
            tvb(2, 2):uint(), az, bins)
    elseif id == 123 then
        if n < 10 then tree:add_proto_expert_info(e_short); return "Navigation (short)" end
        tree:add(f.nav_azimuth, tvb(0, 2))
        tree:add(f.nav_seconds, tvb(2, 4))
        tree:add(f.nav_split, tvb(6, 4))
        local peaks = math.floor((n - 10) / 6)
        tree:add(f.nav_peaks, tvb(0, 0), peaks)
        for k = 0, peaks - 1 do
            tree:add(f.nav_range, tvb(10 + 6 * k, 4))
            tree:add(f.nav_power, tvb(14 + 6 * k, 2))
        end
        return string.format("Navigation az=%d peaks=%d", tvb(0, 2):uint(), peaks)
    end
    if n > 0 then tree:add(f.payload, tvb(0, n)) end
    return msg_names[id] or string.format("Message %d", id)
end

-- Length of the message starting at `offset`, or nil when more bytes are needed to tell.
-- For bytes that do not start with a signature, the "message" is the junk up to the next
-- signature (or the rest of the segment), so the stream resynchronises instead of being
-- misparsed.
local function pdu_len(tvb, offset)
    local avail = tvb:len() - offset
    if avail < 16 then
        -- a signature cut by the segment's end: ask for the next segment
        if tvb:raw(offset, avail) == string.sub(SIGNATURE, 1, avail) then return nil end
        return avail
    end
    if tvb:raw(offset, 16) ~= SIGNATURE then
        local nxt = find_signature(tvb, offset + 1)
        if nxt == nil then return avail end
        return nxt - offset
    end
    if avail < HEADER_BYTES then return nil end
    local size = tvb(offset + 18, 4):uint()
    if size > MAX_PAYLOAD or tvb(offset + 16, 1):uint() ~= 1 then
        -- corrupt header: like the module's decoder, resynchronise from the next byte
        local nxt = find_signature(tvb, offset + 1)
        if nxt == nil then return avail end
        return nxt - offset
    end
    return HEADER_BYTES + size
end

local function dissect_pdu(tvb, pinfo, tree)
    local n = tvb:len()
    pinfo.cols.protocol = "Colossus"
    if n < 16 or tvb:raw(0, 16) ~= SIGNATURE then
        local t = tree:add(p, tvb(), "Colossus junk")
        t:add(f.junk, tvb())
        t:add(f.junk_len, tvb(), n)
        t:add_proto_expert_info(e_junk)
        pinfo.cols.info:append(string.format(" [junk %d bytes]", n))
        return n
    end
    local id = tvb(17, 1):uint()
    local size = tvb(18, 4):uint()
    if n < HEADER_BYTES or tvb(16, 1):uint() ~= 1 or size > MAX_PAYLOAD then
        -- an invalid header: shown, but not counted as a message (colossus.id stays unset)
        local t = tree:add(p, tvb(), "Colossus invalid header")
        t:add(f.signature, tvb(0, 16))
        if n >= HEADER_BYTES then
            local vi = t:add(f.version, tvb(16, 1))
            local si = t:add(f.payload_len, tvb(18, 4))
            if tvb(16, 1):uint() ~= 1 then vi:add_proto_expert_info(e_bad_version) end
            if size > MAX_PAYLOAD then si:add_proto_expert_info(e_oversize) end
        end
        t:add(f.junk, tvb())
        t:add(f.junk_len, tvb(), n)
        t:add_proto_expert_info(e_junk)
        pinfo.cols.info:append(" [invalid header]")
        return n
    end
    local t = tree:add(p, tvb(), "Colossus, " .. (msg_names[id] or ("id " .. id)))
    t:add(f.signature, tvb(0, 16))
    t:add(f.version, tvb(16, 1))
    t:add(f.id, tvb(17, 1))
    t:add(f.payload_len, tvb(18, 4))
    local info = dissect_payload(id, tvb(HEADER_BYTES, n - HEADER_BYTES):tvb(), t, pinfo)
    if tostring(pinfo.cols.info) == "" or string.find(tostring(pinfo.cols.info), "Colossus:", 1, true) == nil then
        pinfo.cols.info = "Colossus: " .. info
    else
        pinfo.cols.info:append(" | " .. info)
    end
    return n
end

-- TCP reassembly through pinfo.desegment_offset / desegment_len (several messages per
-- segment, one message over many segments).
function p.dissector(tvb, pinfo, tree)
    local n, offset = tvb:len(), 0
    while offset < n do
        local len = pdu_len(tvb, offset)
        if len == nil then
            pinfo.desegment_offset = offset
            pinfo.desegment_len = DESEGMENT_ONE_MORE_SEGMENT
            return n
        end
        if offset + len > n then
            pinfo.desegment_offset = offset
            pinfo.desegment_len = offset + len - n
            return n
        end
        dissect_pdu(tvb(offset, len):tvb(), pinfo, tree)
        offset = offset + len
    end
    return n
end

local function heuristic(tvb, pinfo, tree)
    if tvb:len() < 16 or tvb:raw(0, 16) ~= SIGNATURE then return false end
    pinfo.conversation = p
    p.dissector(tvb, pinfo, tree)
    return true
end

local registered_port = nil
function p.init()
    learnt_encoder = nil
    local tcp = DissectorTable.get("tcp.port")
    if registered_port ~= nil then tcp:remove(registered_port, p) end
    registered_port = p.prefs.port
    tcp:add(registered_port, p)
end

p:register_heuristic("tcp", heuristic)
