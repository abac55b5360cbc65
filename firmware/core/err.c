// SPDX-License-Identifier: MIT
#include "shadowlean/sl_err.h"

const char *sl_err_str(sl_err_t err)
{
    switch (err) {
    case SL_OK: return "SL_OK";
    case SL_ERR_ARG: return "SL_ERR_ARG";
    case SL_ERR_NEED_MORE: return "SL_ERR_NEED_MORE";
    case SL_ERR_MALFORMED: return "SL_ERR_MALFORMED";
    case SL_ERR_FULL: return "SL_ERR_FULL";
    case SL_ERR_BUSY: return "SL_ERR_BUSY";
    case SL_ERR_PORT: return "SL_ERR_PORT";
    case SL_ERR_RANGE: return "SL_ERR_RANGE";
    case SL_ERR_STATE: return "SL_ERR_STATE";
    case SL_ERR_CAL_SIZE: return "SL_ERR_CAL_SIZE";
    case SL_ERR_CAL_MAGIC: return "SL_ERR_CAL_MAGIC";
    case SL_ERR_CAL_VERSION: return "SL_ERR_CAL_VERSION";
    case SL_ERR_CAL_CRC: return "SL_ERR_CAL_CRC";
    case SL_ERR_CAL_BOARD: return "SL_ERR_CAL_BOARD";
    case SL_ERR_CAL_AZIMUTHS: return "SL_ERR_CAL_AZIMUTHS";
    case SL_ERR_CAL_VALUE: return "SL_ERR_CAL_VALUE";
    case SL_ERR_CAL_WORKSPACE: return "SL_ERR_CAL_WORKSPACE";
    }
    return "SL_ERR_?";
}
