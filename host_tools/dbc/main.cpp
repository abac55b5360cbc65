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
#include "sl_dbc.h"

namespace {
int usage()
{
    std::cerr << "usage: sl-dbc BOARD [--out FILE]\n"
                 "  BOARD: a board name under boards/ or a path to a board.ini\n";
    return 2;
}
} // namespace

int main(int argc, char **argv)
{
    std::string board, out;
    for (int i = 1; i < argc; i++) {
        const std::string a = argv[i];
        if (a == "--out" && i + 1 < argc) {
            out = argv[++i];
        } else if (a == "-h" || a == "--help") {
            usage();
            return 0;
        } else if (!a.empty() && a[0] != '-' && board.empty()) {
            board = a;
        } else {
            return usage();
        }
    }
    if (board.empty()) {
        return usage();
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
