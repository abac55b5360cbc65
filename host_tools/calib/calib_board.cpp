// SPDX-License-Identifier: MIT
// calib_board.cpp: see calib_board.h.
#include "calib_board.h"

#include <cstdlib>
#include <map>
#include <mutex>
#include <utility>
#include <memory>
#include <stdexcept>
#include <vector>

#include "calib_file.h"
#include "shadowlean/sl_calblob.h"

namespace sl {

namespace {

struct Calibrated {
    std::vector<uint8_t> blob;
    std::unique_ptr<sl_calblob_ws_t> ws{new sl_calblob_ws_t()};
    sl_board_t view{};
};

} // namespace

const sl_board_t *core_board(const std::string &name, const std::string &calibration)
{
    const sl_board_t *nominal = sl_board_find(name.c_str());
    if (nominal == nullptr) {
        throw std::runtime_error("board " + name + " is not linked into the core (sl_board_find)");
    }
    if (calibration.empty()) {
        return nominal;
    }
    // One view per (board, file), made once and alive until exit (views are borrowed by
    // pipelines, possibly in several threads: sl-eval's workers).
    static std::mutex mu;
    static std::map<std::pair<std::string, std::string>, std::unique_ptr<Calibrated>> keep;
    std::lock_guard<std::mutex> lock(mu);
    const auto key = std::make_pair(name, calibration);
    const auto it = keep.find(key);
    if (it != keep.end()) {
        return &it->second->view;
    }
    std::unique_ptr<Calibrated> c(new Calibrated());
    uint8_t *raw = nullptr;
    size_t len = 0;
    char err[512];
    if (slp_calib_file_load(calibration.c_str(), nominal, &raw, &len, err, sizeof err) != 0) {
        throw std::runtime_error(std::string("calibration ") + err);
    }
    c->blob.assign(raw, raw + len);
    std::free(raw);
    sl_calblob_info_t info{};
    const sl_err_t e = sl_calblob_open(c->blob.data(), c->blob.size(), nominal, c->ws.get(), &c->view, &info);
    if (e != SL_OK) {
        throw std::runtime_error("calibration " + calibration + " rejected for board " + name + ": " +
                                 sl_err_str(e) + " (" + (info.what != nullptr ? info.what : "?") + ", entry " +
                                 std::to_string(info.index) + ")");
    }
    const sl_board_t *v = &c->view;
    keep[key] = std::move(c);
    return v;
}

} // namespace sl
