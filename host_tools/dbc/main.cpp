// SPDX-License-Identifier: MIT
// sl-dbc: the DBC file of a board's CAN interface.
//
//   sl-dbc BOARD [--out FILE]
//
// BOARD is a name under boards/ or a path to a board.ini. Without --out the DBC goes to
// stdout. The table generator sl-tables writes the same text (sl::make_dbc) to
// boards/<name>/shadowlean.dbc; this tool exists to run and test it standalone.
#include <cstdio>
#include <fstream>
#include <iostream>
#include <string>

#include "sl_board_spec.h"
#include "sl_cli.h"
#include "sl_dbc.h"

namespace {
void usage(FILE *f)
{
    std::fputs("usage: sl-dbc BOARD [--out FILE]\n"
               "  BOARD: a board name under boards/ or a path to a board.ini\n",
               f);
}
} // namespace

int main(int argc, char **argv)
{
    std::string board, out;
    const int info = sl_cli_info(argc, argv, "sl-dbc", usage);
    if (info != SL_CLI_CONTINUE) {
        return info;
    }
    for (int i = 1; i < argc; i++) {
        const std::string a = argv[i];
        if (a == "--out") {
            if (i + 1 >= argc) {
                return sl_cli_bad_value("sl-dbc", "--out", "needs a value", usage);
            }
            out = argv[++i];
        } else if (!a.empty() && a[0] != '-' && board.empty()) {
            board = a;
        } else {
            return sl_cli_unknown("sl-dbc", argv[i], usage);
        }
    }
    if (board.empty()) {
        return sl_cli_usage_error("sl-dbc", "missing BOARD", usage);
    }
    try {
        const sl::BoardSpec b = sl::load_board(board);
        const std::string dbc = sl::make_dbc(b);
        if (out.empty()) {
            std::cout << dbc;
            return std::cout.good() ? 0 : 1;
        }
        std::ofstream f(out, std::ios::binary | std::ios::trunc);
        f << dbc;
        f.close();
        if (!f) {
            std::cerr << "sl-dbc: cannot write " << out << "\n";
            return 1;
        }
        return 0;
    } catch (const std::exception &e) {
        std::cerr << "sl-dbc: " << e.what() << "\n";
        return 1;
    }
}
