#include "pose_options.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <initializer_list>
#include <vector>

#include "cli_common.hpp"
#include "rccx/io/parse.hpp"
#include "rccx/math/units.hpp"

namespace rccx::tools {
namespace {

struct Unit {
  std::string_view name;
  double scale;  ///< to SI (m, rad)
};

/// A number with one of `units` after it (or none: the first, the SI one), its magnitude within
/// `max_si`.
/// `kind` ("a length", "an angle") and `range` (the bound as people read it) go in the messages.
double parse_with_unit(std::string_view text, std::string_view what, std::string_view kind,
                       std::initializer_list<Unit> units, double max_si, std::string_view range) {
  // The unit is the trailing run of letters; "1e3" ends in a digit, so has none.
  std::size_t cut = text.size();
  while (cut > 0 && std::isalpha(static_cast<unsigned char>(text[cut - 1])) != 0) --cut;
  const std::string_view number = text.substr(0, cut);
  const std::string_view unit = text.substr(cut);
  std::string names;
  for (const Unit& u : units) names += fmt::format("{}{}", names.empty() ? "" : " or ", u.name);
  const auto found =
      std::find_if(units.begin(), units.end(), [&](const Unit& u) { return u.name == unit; });
  if (number.empty() || (!unit.empty() && found == units.end())) {
    throw io::ParseError(
        fmt::format("{}: {} is not {}; write a number with {} (a bare number is {}), {}", what,
                    io::quoted(text), kind, names, units.begin()->name, range));
  }
  const double v = io::parse_number(number, what) * (unit.empty() ? 1.0 : found->scale);
  if (!(std::abs(v) <= max_si)) {
    throw io::ParseError(
        fmt::format("{}: {} is out of range; give {} {}", what, io::quoted(text), kind, range));
  }
  return v;
}

/// The comma-separated items of `text`, exactly `count` of them.
std::vector<std::string_view> items(std::string_view text, std::string_view what,
                                    std::size_t count) {
  std::vector<std::string_view> out;
  for (std::size_t start = 0;;) {
    const std::size_t comma = text.find(',', start);
    out.push_back(text.substr(start, comma - start));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  if (out.size() != count) {
    throw io::ParseError(
        fmt::format("{}: {} values given, {} needed (comma-separated)", what, out.size(), count));
  }
  return out;
}

/// Throws BadArgument unless R is a rotation: a pose with a sheared or scaled rotation is no
/// frame, and has no joint solution.
void check_rotation(const math::Rot3& R, std::string_view what) {
  const math::Rot3 RtR = R.transposed() * R;
  double error = 0.0;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) error = std::max(error, std::abs(RtR(r, c) - (r == c ? 1.0 : 0.0)));
  }
  const double det = math::dot(math::cross(R.n, R.o), R.a);
  if (error > 1e-6 || det < 0) {
    throw BadArgument{fmt::format(
        "{}: the rotation part is not a rotation matrix (|RtR - I| = {:.2g}, det = {:.6g}); give "
        "the nine r numbers of an orthonormal, right-handed frame",
        what, error, det)};
  }
}

}  // namespace

double parse_length(std::string_view text, std::string_view what, double max_m) {
  return parse_with_unit(text, what, "a length", {{"m", 1.0}, {"mm", 1e-3}}, max_m,
                         fmt::format("within +-{:g} m (0.325m, 325mm)", max_m));
}

double parse_angle(std::string_view text, std::string_view what) {
  return parse_with_unit(text, what, "an angle", {{"rad", 1.0}, {"deg", math::kPi / 180.0}},
                         2 * math::kPi, "within one turn, +-360deg or +-6.2832rad (90deg, 1.5708)");
}

void add_pose_options(CLI::App& cmd, PoseArgs& pose, std::string_view frame) {
  CLI::Option* t = cmd.add_option(
      "--T", pose.T,
      fmt::format("{} as 12 comma-separated numbers, row by row: r11,r12,r13,px,r21,r22,r23,py,"
                  "r31,r32,r33,pz (r: rotation matrix, p: position in m)",
                  frame));
  CLI::Option* xyz = cmd.add_option(
      "--xyz", pose.xyz,
      "Instead of --T, with --rpy: the position X,Y,Z with m or mm (0.325m,150mm,0.25; a bare "
      "number is m)");
  CLI::Option* rpy = cmd.add_option(
      "--rpy", pose.rpy,
      "With --xyz: the orientation as URDF's roll,pitch,yaw about the fixed axes (roll about x, "
      "then pitch about y, then yaw about z; not Paul's, whose roll is about z), with deg or rad "
      "(180deg,0,90deg; a bare number is rad)");
  for (CLI::Option* o : {t, xyz, rpy}) o->check(not_empty());
  t->excludes(xyz)->excludes(rpy);
  xyz->needs(rpy);
  rpy->needs(xyz);
}

math::Transform pose_from(const PoseArgs& pose, double max_position_m) {
  if (pose.T.empty() && pose.xyz.empty()) {
    throw BadArgument{"a pose is needed: give --T (12 numbers), or --xyz and --rpy"};
  }
  if (!pose.T.empty()) {
    const std::vector<double> v = io::parse_number_list(
        pose.T, "--T", 12, {-max_position_m, max_position_m, "(m for px, py, pz)"});
    std::array<double, 12> rows{};
    std::copy(v.begin(), v.end(), rows.begin());
    const math::Transform T = math::Transform::from_rows(rows);
    check_rotation(T.R, "--T");
    return T;
  }
  std::array<double, 3> p{};
  std::array<double, 3> a{};
  const auto xyz = items(pose.xyz, "--xyz", 3);
  const auto rpy = items(pose.rpy, "--rpy", 3);
  for (std::size_t i = 0; i < 3; ++i) {
    p[i] = parse_length(xyz[i], fmt::format("--xyz ({})", "xyz"[i]), max_position_m);
    a[i] = parse_angle(rpy[i], fmt::format("--rpy ({})", std::array{"roll", "pitch", "yaw"}[i]));
  }
  return {math::Rot3::from_urdf_rpy(a[0], a[1], a[2]), {p[0], p[1], p[2]}};
}

}  // namespace rccx::tools
