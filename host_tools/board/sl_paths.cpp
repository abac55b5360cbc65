// SPDX-License-Identifier: MIT
#include "sl_paths.h"

#include <cstdlib>
#include <sys/stat.h>

namespace sl {

std::string source_dir()
{
    const char *env = std::getenv("SL_SOURCE_DIR");
    return (env != nullptr && *env != '\0') ? std::string(env) : std::string(SL_SOURCE_DIR);
}

std::string board_dir(const std::string &name)
{
    struct stat st {};
    if (name.find('/') != std::string::npos && stat(name.c_str(), &st) == 0) {
        if (S_ISDIR(st.st_mode)) {
            return name;
        }
        const auto slash = name.rfind('/');
        return name.substr(0, slash);
    }
    return source_dir() + "/boards/" + name;
}

} // namespace sl
