// Where rccx's shipped data is (cells/*.json, robots/*.json), for programs in the source tree
// and for programs built against an installed rccx alike:
//
//   const std::filesystem::path cell = io::find_data_file("cells/cvarl.json");
//
// The places looked in, first to last (data_dirs()):
//   1. $RCCX_DATA_DIR, when set and not empty: then the only place (a wrong one is an error,
//      not a silent fallback);
//   2. the installed share/rccx this program was compiled against: `cmake --install` writes
//      rccx/io/installed_data_dir.hpp beside this header with the prefix it installed to, so a
//      program built with find_package(rccx) or `pkg-config rccx` finds it wherever that is;
//   3. the source tree the library was built from (a program of the tree, examples/);
//   4. share/rccx under the CMAKE_INSTALL_PREFIX the library was configured with.
#pragma once

#include <filesystem>
#include <stdexcept>
#include <string_view>
#include <vector>

#if __has_include("installed_data_dir.hpp")
#include "installed_data_dir.hpp"  // RCCX_INSTALLED_DATA_DIR, written by cmake --install
#endif
#ifndef RCCX_INSTALLED_DATA_DIR
#define RCCX_INSTALLED_DATA_DIR ""  // the source tree: no installed copy to prefer
#endif

namespace rccx::io {

/// A data file found in none of the places looked in; the message names them and what to set.
class DataFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The directories searched for rccx's data, in order (see the top of this file). The
/// default argument is expanded where the function is called: the installed directory of the
/// headers that program was compiled with.
std::vector<std::filesystem::path> data_dirs(
    std::string_view installed_dir = RCCX_INSTALLED_DATA_DIR);

/// `relative` (such as "cells/cvarl.json") in the first of data_dirs() that holds it. Throws
/// DataFileError naming every directory looked in and RCCX_DATA_DIR.
std::filesystem::path find_data_file(const std::filesystem::path& relative,
                                     std::string_view installed_dir = RCCX_INSTALLED_DATA_DIR);

}  // namespace rccx::io
