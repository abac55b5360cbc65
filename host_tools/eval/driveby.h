// SPDX-License-Identifier: MIT
// driveby.h: `sl-eval driveby`, the 3D tilt fit end to end on simulated drive-bys.
#pragma once

/// Runs `sl-eval driveby` with the arguments after the command. Returns the exit status.
int cmd_driveby(int argc, char **argv);
