-- SPDX-License-Identifier: MIT
-- shadowlean_can.lua: Wireshark / tshark dissector for the CAN frames of a shadowlean
-- module (PoleLean, LeanWarning, Status, Health, PoleTilt, GroundPlane, GroundHazard,
-- VehicleMotion) on SocketCAN captures (candump/SocketCAN pcap, link type 227), with the
-- AUTOSAR E2E Profile 11 check.
--
-- Everything comes from the board's generated DBC (boards/<board>/shadowlean.dbc, installed
-- as /usr/share/shadowlean/dbc/<board>.dbc): ids (11-bit, or 29-bit: DBC ids with bit 31
-- set), signal layouts and scaling, value tables, each message's E2E Data ID (attribute
-- SlE2EDataId) and mode (SlE2EMode: Both = 11A, Nibble = 11C). Frames whose id the DBC
-- does not know are left to other dissectors.
--
--     tshark -X lua_script:shadowlean_can.lua -o shadowlean.dbc:/usr/share/shadowlean/dbc/paper-sim.dbc \
--            -r can.pcapng -Y shadowlean
--     tshark ... -Y 'shadowlean.e2e.status != "OK"'       frames the Profile 11 check did not accept
--
-- E2E Profile 11 (default offsets): byte 0 = CRC-8 (polynomial 0x1D, start value 0x00, not
-- reflected, no final XOR) over the Data ID's low byte, then its high byte (11A) or 0x00
-- (11C), then data bytes 1..7; bits 8..11 = counter 0..14; in 11C bits 12..15 = the Data
-- ID's bits 8..11. The check status of each frame (one sequence per message, in capture
-- order): INITIAL (the first of its message), OK (counter step 1), OK_SOME_LOST (2 ..
-- max delta counter, preference shadowlean.max_delta_counter, default 1), REPEATED (0),
-- WRONG_SEQUENCE (larger), ERROR (length, CRC, Data ID nibble or counter 15).
--
-- Fields: shadowlean.message, shadowlean.data_id, shadowlean.mode, shadowlean.crc,
-- shadowlean.crc.computed, shadowlean.crc.status ("good" / "bad"), shadowlean.counter,
-- shadowlean.e2e.status, shadowlean.signal ("Name=value" per signal, physical value).

local p = Proto("shadowlean", "shadowlean CAN (pole lean, E2E Profile 11)")

local f_msg = ProtoField.string("shadowlean.message", "Message")
local f_data_id = ProtoField.uint16("shadowlean.data_id", "E2E Data ID", base.HEX)
local f_mode = ProtoField.string("shadowlean.mode", "E2E Profile 11 mode")
local f_crc = ProtoField.uint8("shadowlean.crc", "CRC", base.HEX)
local f_crc_calc = ProtoField.uint8("shadowlean.crc.computed", "CRC computed", base.HEX)
local f_crc_status = ProtoField.string("shadowlean.crc.status", "CRC status")
local f_counter = ProtoField.uint8("shadowlean.counter", "Counter", base.DEC)
local f_e2e = ProtoField.string("shadowlean.e2e.status", "E2E Profile 11 status")
local f_signal = ProtoField.string("shadowlean.signal", "Signal")
p.fields = {f_msg, f_data_id, f_mode, f_crc, f_crc_calc, f_crc_status, f_counter, f_e2e, f_signal}

local e_crc = ProtoExpert.new("shadowlean.crc.bad", "E2E CRC mismatch", expert.group.CHECKSUM,
                              expert.severity.ERROR)
local e_e2e = ProtoExpert.new("shadowlean.e2e.rejected", "E2E Profile 11 check did not accept the frame",
                              expert.group.SEQUENCE, expert.severity.WARN)
p.experts = {e_crc, e_e2e}

p.prefs.dbc = Pref.string("DBC file", "/usr/share/shadowlean/dbc/paper-sim.dbc",
                          "The board's generated DBC (boards/<board>/shadowlean.dbc)")
p.prefs.max_delta_counter = Pref.uint("Max delta counter", 1,
                                      "Largest counter step that is OK_SOME_LOST (1..14)")

local can_id_field = Field.new("can.id")
local can_xtd_field = Field.new("can.flags.xtd")

local db = nil        -- DBC-style id -> message {name, size, data_id, nibble, signals, values}
local db_error = nil
local seq = {}        -- message name -> counter of the last frame with a valid CRC
local memo = {}       -- frame number -> {status, ...} (the check runs once, in capture order)

-- ---------------------------------------------------------------------------------------
-- DBC

local function load_dbc(path)
    local fh, err = io.open(path, "r")
    if not fh then
        return nil, "shadowlean: cannot open DBC " .. tostring(path) .. ": " .. tostring(err)
    end
    local msgs, cur = {}, nil
    for line in fh:lines() do
        local id, name, size = line:match("^BO_%s+(%d+)%s+([%w_]+)%s*:%s*(%d+)")
        if id then
            cur = {name = name, size = tonumber(size), data_id = 0, nibble = false, signals = {},
                   values = {}}
            msgs[tonumber(id)] = cur
        else
            local sname, start, len, order, sign, factor, offset, unit = line:match(
                '^%s+SG_%s+([%w_]+)%s*:%s*(%d+)|(%d+)@([01])([%+%-])%s*%(([^,]+),([^%)]+)%)%s*%[[^%]]*%]%s*"([^"]*)"')
            if sname and cur then
                table.insert(cur.signals, {name = sname, start = tonumber(start), len = tonumber(len),
                                           intel = order == "1", signed = sign == "-",
                                           factor = tonumber(factor), offset = tonumber(offset),
                                           unit = unit})
            elseif not line:match("^%s+SG_") then
                cur = nil
            end
            local aid, v = line:match('^BA_%s+"SlE2EDataId"%s+BO_%s+(%d+)%s+(%d+)')
            if aid and msgs[tonumber(aid)] then
                msgs[tonumber(aid)].data_id = tonumber(v)
            end
            aid, v = line:match('^BA_%s+"SlE2EMode"%s+BO_%s+(%d+)%s+(%d+)')
            if aid and msgs[tonumber(aid)] then
                msgs[tonumber(aid)].nibble = tonumber(v) == 1
            end
            local vid, vsig, rest = line:match("^VAL_%s+(%d+)%s+([%w_]+)%s+(.*);")
            if vid and msgs[tonumber(vid)] then
                local t = {}
                for num, txt in rest:gmatch('(%d+)%s+"([^"]*)"') do
                    t[tonumber(num)] = txt
                end
                msgs[tonumber(vid)].values[vsig] = t
            end
        end
    end
    fh:close()
    return msgs, nil
end

local reported = nil -- the DBC error already reported (once per path)

local function reload()
    db, db_error = load_dbc(p.prefs.dbc)
    if db_error ~= nil and reported ~= db_error then
        reported = db_error
        report_failure(db_error .. " (set the preference shadowlean.dbc to the board's DBC)")
    end
end

function p.prefs_changed()
    reload()
    seq, memo = {}, {}
end

function p.init()
    seq, memo = {}, {}
    if db == nil then
        reload()
    end
end

-- ---------------------------------------------------------------------------------------
-- E2E Profile 11

local function crc8_0x1d(crc, bytes)
    for _, b in ipairs(bytes) do
        crc = bit32.bxor(crc, b)
        for _ = 1, 8 do
            if bit32.band(crc, 0x80) ~= 0 then
                crc = bit32.band(bit32.bxor(bit32.lshift(crc, 1), 0x1D), 0xFF)
            else
                crc = bit32.band(bit32.lshift(crc, 1), 0xFF)
            end
        end
    end
    return crc
end

local function p11_crc(data_id, nibble, d)
    local hi = nibble and 0 or bit32.band(bit32.rshift(data_id, 8), 0xFF)
    local input = {bit32.band(data_id, 0xFF), hi}
    for i = 2, 8 do
        input[#input + 1] = d[i]
    end
    return crc8_0x1d(0, input)
end

local function check(m, d, len)
    local r = {}
    if len ~= m.size or len ~= 8 then
        r.status = "ERROR"
        return r
    end
    r.crc = d[1]
    r.crc_calc = p11_crc(m.data_id, m.nibble, d)
    r.counter = bit32.band(d[2], 0x0F)
    if r.crc ~= r.crc_calc then
        r.status = "ERROR"
        return r
    end
    if m.nibble and bit32.rshift(d[2], 4) ~= bit32.band(bit32.rshift(m.data_id, 8), 0x0F) then
        r.status = "ERROR"
        return r
    end
    if r.counter >= 15 then
        r.status = "ERROR"
        return r
    end
    local last = seq[m.name]
    seq[m.name] = r.counter -- Profile 11: the state follows every frame with a valid CRC
    if last == nil then
        r.status = "INITIAL"
        return r
    end
    local delta = (r.counter - last) % 15
    local max_delta = math.max(1, math.min(14, p.prefs.max_delta_counter))
    if delta == 0 then
        r.status = "REPEATED"
    elseif delta == 1 then
        r.status = "OK"
    elseif delta <= max_delta then
        r.status = "OK_SOME_LOST"
    else
        r.status = "WRONG_SEQUENCE"
    end
    return r
end

-- ---------------------------------------------------------------------------------------
-- Signals (Intel byte order, as every shadowlean signal)

local function raw_value(d, s)
    local v = 0
    for k = 0, s.len - 1 do
        local pos = s.start + k
        local byte = d[math.floor(pos / 8) + 1] or 0
        if bit32.band(bit32.rshift(byte, pos % 8), 1) ~= 0 then
            v = v + 2 ^ k
        end
    end
    if s.signed and v >= 2 ^ (s.len - 1) then
        v = v - 2 ^ s.len
    end
    return v
end

local function fmt(x)
    local s = string.format("%.6f", x):gsub("0+$", ""):gsub("%.$", "")
    if s == "-0" then
        s = "0"
    end
    return s
end

-- ---------------------------------------------------------------------------------------

local function dissect(tvb, pinfo, tree)
    if db == nil then
        return false
    end
    local ids = {can_id_field()}
    local xtd = {can_xtd_field()}
    if #ids == 0 then
        return false
    end
    local id = ids[#ids].value
    if #xtd > 0 and xtd[#xtd].value then
        id = id + 0x80000000 -- DBC style
    end
    local m = db[id]
    if m == nil then
        return false
    end
    local len = tvb:len()
    local d = {}
    for i = 0, len - 1 do
        d[i + 1] = tvb(i, 1):uint()
    end
    local r = memo[pinfo.number]
    if r == nil then
        r = check(m, d, len)
        memo[pinfo.number] = r
    end
    pinfo.cols.protocol = "shadowlean"
    pinfo.cols.info = m.name .. " E2E " .. r.status
    local t = tree:add(p, tvb(), "shadowlean " .. m.name)
    t:add(f_msg, m.name)
    t:add(f_data_id, m.data_id)
    t:add(f_mode, m.nibble and "11C (nibble)" or "11A (both)")
    if r.crc ~= nil then
        local ci = t:add(f_crc, tvb(0, 1))
        t:add(f_crc_calc, r.crc_calc):set_generated()
        t:add(f_crc_status, r.crc == r.crc_calc and "good" or "bad"):set_generated()
        if r.crc ~= r.crc_calc then
            ci:add_proto_expert_info(e_crc)
        end
        t:add(f_counter, tvb(1, 1), r.counter)
    end
    local ei = t:add(f_e2e, r.status)
    ei:set_generated()
    if r.status ~= "OK" and r.status ~= "INITIAL" and r.status ~= "OK_SOME_LOST" then
        ei:add_proto_expert_info(e_e2e)
    end
    if len == m.size then
        for _, s in ipairs(m.signals) do
            local raw = raw_value(d, s)
            local phys = raw * s.factor + s.offset
            local txt = s.name .. "=" .. fmt(phys)
            local names = m.values[s.name]
            if names and names[raw] then
                txt = txt .. " (" .. names[raw] .. ")"
            end
            if s.unit ~= "" then
                txt = txt .. " " .. s.unit
            end
            t:add(f_signal, tvb(math.floor(s.start / 8), 1), txt)
        end
    end
    return true
end

p:register_heuristic("can", dissect)
