// SPDX-License-Identifier: MIT
// check_view.cpp: checks on sl-view's output (tests/host/view).
//
//   check_view png FILE [--size W H] [--min COLOUR N]...   COLOUR: amber magenta red cyan green orange
//   check_view video FILE FRAMES                           (FILE.mp4, or FILE.avi fallback)
//
// A colour is counted with a small tolerance on pixels of exactly the tool's overlay colours
// (view_draw.h col::*), so a missing overlay fails the test. Prints what it measured.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <string>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include "view_draw.h"

namespace {

int count_colour(const cv::Mat &img, const cv::Scalar &c)
{
    cv::Mat m;
    const cv::Scalar lo(std::max(0.0, c[0] - 12), std::max(0.0, c[1] - 12), std::max(0.0, c[2] - 12));
    const cv::Scalar hi(std::min(255.0, c[0] + 12), std::min(255.0, c[1] + 12), std::min(255.0, c[2] + 12));
    cv::inRange(img, lo, hi, m);
    return cv::countNonZero(m);
}

} // namespace

int main(int argc, char **argv)
{
    if (argc < 3) {
        std::fprintf(stderr, "usage: check_view png FILE [...] | video FILE FRAMES\n");
        return 2;
    }
    const std::string mode = argv[1], file = argv[2];
    int fail = 0;
    if (mode == "png") {
        const cv::Mat img = cv::imread(file, cv::IMREAD_COLOR);
        if (img.empty()) {
            std::printf("FAIL %s: cannot read\n", file.c_str());
            return 1;
        }
        std::printf("%s: %d x %d\n", file.c_str(), img.cols, img.rows);
        const std::map<std::string, cv::Scalar> colours = {
            {"amber", sl::col::kBoardShadow}, {"magenta", sl::col::kCalibShadow},
            {"red", sl::col::kDetect},        {"cyan", sl::col::kTruth},
            {"blue", sl::col::kNearField},
            {"orange", cv::Scalar(0, 140, 255)}}; // fitted 3D tilt (host_tools/view/view_tilt_draw.inl)
        for (int i = 3; i < argc; i++) {
            if (!std::strcmp(argv[i], "--size") && i + 2 < argc) {
                const int w = std::atoi(argv[i + 1]), h = std::atoi(argv[i + 2]);
                if (img.cols != w || img.rows != h) {
                    std::printf("FAIL size %d x %d, expected %d x %d\n", img.cols, img.rows, w, h);
                    fail++;
                }
                i += 2;
            } else if (!std::strcmp(argv[i], "--min") && i + 2 < argc) {
                auto it = colours.find(argv[i + 1]);
                if (it == colours.end()) {
                    std::printf("FAIL unknown colour %s\n", argv[i + 1]);
                    return 2;
                }
                const int n = count_colour(img, it->second), want = std::atoi(argv[i + 2]);
                std::printf("  %s pixels: %d (want >= %d)\n", argv[i + 1], n, want);
                if (n < want) fail++;
                i += 2;
            } else if (!std::strcmp(argv[i], "--max") && i + 2 < argc) {
                auto it = colours.find(argv[i + 1]);
                if (it == colours.end()) return 2;
                const int n = count_colour(img, it->second), want = std::atoi(argv[i + 2]);
                std::printf("  %s pixels: %d (want <= %d)\n", argv[i + 1], n, want);
                if (n > want) fail++;
                i += 2;
            }
        }
    } else if (mode == "video" && argc >= 4) {
        std::string f = file;
        cv::VideoCapture cap(f);
        if (!cap.isOpened()) {
            f = file.substr(0, file.rfind('.')) + ".avi";
            cap.open(f);
        }
        if (!cap.isOpened()) {
            std::printf("FAIL cannot open %s (nor .avi)\n", file.c_str());
            return 1;
        }
        int n = 0;
        cv::Mat fr;
        while (cap.read(fr)) n++;
        std::printf("%s: %d frames of %d x %d\n", f.c_str(), n, fr.empty() ? 0 : fr.cols, fr.empty() ? 0 : fr.rows);
        if (n != std::atoi(argv[3])) {
            std::printf("FAIL %d frames, expected %s\n", n, argv[3]);
            fail++;
        }
    } else {
        return 2;
    }
    std::printf("%s\n", fail ? "FAILED" : "ok");
    return fail ? 1 : 0;
}
