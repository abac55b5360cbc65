// SPDX-License-Identifier: MIT
// sl-eval terrain: the ground module on simulated terrain and attitude (terrain.cpp).
#pragma once

/// `sl-eval terrain` with its arguments (after the subcommand). Returns the exit code.
int cmd_terrain(int argc, char **argv);
