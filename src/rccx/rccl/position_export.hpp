// The position database as JSON (`rccx db export` / `rccx db import`), to keep positions in
// version control or edit them off-line:
//
//   {
//     "rccx_position_database": 1,            // PositionDb::kSchemaVersion, an integer
//     "units": "m, rad; ...",                 // optional, for people
//     "transforms": [
//       {"robot": "microbo", "name": "PICK",
//        "T_rows_m": [r11, r12, r13, px, r21, r22, r23, py, r31, r32, r33, pz],  // m
//        "configuration": "n", "note": "...",                   // optional
//        "created_unix_s": 1700000000, "changed_unix_s": 1700000000}            // optional
//     ]
//   }
//
// The reader takes exactly this: unknown or repeated keys, a wrong type, 13 numbers, a number
// too large for a double, a name or note put() would refuse, and a (robot, name) given twice
// are all refused, naming the transform and the key. Nothing is returned unless all is good.
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "rccx/io/parse.hpp"
#include "rccx/rccl/position_db.hpp"

namespace rccx::rccl {

/// Text that is not a position export: the message names the origin, the transform
/// (index and name) and the key, and says what is expected.
class PositionExportError : public io::ParseError {
 public:
  using io::ParseError::ParseError;
};

/// Every transform of an export, each checked as PositionDb::check does. `origin` names the
/// text in messages (a file name, "standard input"). Throws PositionExportError only.
std::vector<StoredTransform> parse_position_export(std::string_view json_text,
                                                   std::string_view origin);

/// The export of `all` (pretty-printed, ending in a newline). Text that is not UTF-8 (from a
/// file written by another program) is written with U+FFFD in its place rather than refused.
std::string position_export_json(const std::vector<StoredTransform>& all);

/// One transform as the export writes it (for `rccx db show`).
std::string position_json(const StoredTransform& t);

}  // namespace rccx::rccl
