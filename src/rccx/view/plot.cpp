#include "rccx/view/plot.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include "rccx/kinematics/kinematics.hpp"

namespace rccx::view {

namespace {

constexpr std::array<const char*, 8> kColours = {"#d08020", "#2070c0", "#30a030", "#b040b0",
                                                 "#c03030", "#20a0a0", "#909020", "#6050d0"};

using Series = PlotSeries;

std::string escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else
      out += c;
  }
  return out;
}

/// Round steps (1, 2, 5 x 10^k) covering [lo, hi] in about n steps.
std::vector<double> ticks(double lo, double hi, int n = 5) {
  const double span = hi - lo;
  const double raw = span / n;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * mag;
    if (span / step <= n + 0.5) break;
  }
  std::vector<double> out;
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9 * span; v += step) {
    out.push_back(std::abs(v) < 1e-12 * span ? 0.0 : v);
  }
  return out;
}

struct Box {
  double x, y, w, h;  ///< the panel, px
};

/// One panel: a frame, axes with ticks, the series, a legend. `equal`: the same scale on both
/// axes (a path in a plane).
void panel(std::string& svg, const Box& b, const PlotPanel& p) {
  const std::string& title = p.title;
  const std::string& xlabel = p.xlabel;
  const std::string& ylabel = p.ylabel;
  const std::vector<Series>& series = p.series;
  const bool equal = p.equal_axes;
  double x0 = std::numeric_limits<double>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  for (const Series& s : series) {
    for (double v : s.x) x0 = std::min(x0, v), x1 = std::max(x1, v);
    for (double v : s.y) y0 = std::min(y0, v), y1 = std::max(y1, v);
  }
  if (!std::isfinite(x0)) x0 = 0, x1 = 1, y0 = 0, y1 = 1;
  const auto widen = [](double& lo, double& hi) {
    const double pad = std::max((hi - lo) * 0.05, 1e-6 + 1e-3 * std::abs(hi));
    lo -= pad;
    hi += pad;
  };
  widen(x0, x1);
  widen(y0, y1);
  const double L = b.x + 62, R = b.x + b.w - 12, T = b.y + 30, B = b.y + b.h - 40;
  if (equal) {  // the larger span sets the scale of both
    const double sx = (x1 - x0) / (R - L), sy = (y1 - y0) / (B - T);
    const double s = std::max(sx, sy);
    const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    x0 = cx - 0.5 * s * (R - L), x1 = cx + 0.5 * s * (R - L);
    y0 = cy - 0.5 * s * (B - T), y1 = cy + 0.5 * s * (B - T);
  }
  const auto X = [&](double v) { return L + (v - x0) / (x1 - x0) * (R - L); };
  const auto Y = [&](double v) { return B - (v - y0) / (y1 - y0) * (B - T); };
  auto out = std::back_inserter(svg);
  fmt::format_to(out,
                 "<g class=\"panel\"><text x=\"{:.1f}\" y=\"{:.1f}\" class=\"title\">{}</text>\n",
                 b.x + b.w / 2, b.y + 18, escape(title));
  fmt::format_to(
      out, "<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" class=\"frame\"/>\n",
      L, T, R - L, B - T);
  for (double v : ticks(x0, x1)) {
    fmt::format_to(
        out,
        "<line x1=\"{0:.1f}\" x2=\"{0:.1f}\" y1=\"{1:.1f}\" y2=\"{2:.1f}\" class=\"grid\"/>"
        "<text x=\"{0:.1f}\" y=\"{3:.1f}\" class=\"tick\">{4:g}</text>\n",
        X(v), T, B, B + 14, v);
  }
  for (double v : ticks(y0, y1)) {
    fmt::format_to(
        out,
        "<line x1=\"{1:.1f}\" x2=\"{2:.1f}\" y1=\"{0:.1f}\" y2=\"{0:.1f}\" class=\"grid\"/>"
        "<text x=\"{3:.1f}\" y=\"{4:.1f}\" class=\"tick\" text-anchor=\"end\">{5:g}</text>\n",
        Y(v), L, R, L - 4, Y(v) + 4, v);
  }
  fmt::format_to(out, "<text x=\"{:.1f}\" y=\"{:.1f}\" class=\"label\">{}</text>\n", (L + R) / 2,
                 B + 30, escape(xlabel));
  fmt::format_to(out,
                 "<text x=\"{0:.1f}\" y=\"{1:.1f}\" class=\"label\" transform=\"rotate(-90 {0:.1f} "
                 "{1:.1f})\">{2}</text>\n",
                 b.x + 16, (T + B) / 2, escape(ylabel));
  double legend_x = L + 6;
  for (const Series& s : series) {
    if (s.x.empty()) continue;
    // At most about 2000 points a line: the file stays small, the drawing the same.
    const std::size_t every = std::max<std::size_t>(1, s.x.size() / 2000);
    fmt::format_to(out, "<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"{}\"{} points=\"",
                   s.colour, s.width, s.dashed ? " stroke-dasharray=\"5 3\"" : "");
    for (std::size_t i = 0; i < s.x.size(); i += every) {
      fmt::format_to(out, "{:.1f},{:.1f} ", X(s.x[i]), Y(s.y[i]));
    }
    fmt::format_to(out, "{:.1f},{:.1f}\"/>\n", X(s.x.back()), Y(s.y.back()));
    if (!s.label.empty()) {
      fmt::format_to(
          out,
          "<line x1=\"{0:.1f}\" x2=\"{1:.1f}\" y1=\"{2:.1f}\" y2=\"{2:.1f}\" stroke=\"{3}\" "
          "stroke-width=\"2\"{5}/><text x=\"{4:.1f}\" y=\"{6:.1f}\" class=\"legend\">{7}</text>\n",
          legend_x, legend_x + 14, T + 12, s.colour, legend_x + 17,
          s.dashed ? " stroke-dasharray=\"4 2\"" : "", T + 16, escape(s.label));
      legend_x += 30 + 6.6 * static_cast<double>(s.label.size());
    }
  }
  svg += "</g>\n";
}

/// The log's joints must be the robot's.
void check_joints(const RunLog& log, const kin::RobotModel& model) {
  if (log.dof != model.dof()) {
    throw RunLogError(
        fmt::format("the log has {} joints, robot {} has {}: give the robot it was "
                    "recorded with (--robot)",
                    log.dof, model.name, model.dof()));
  }
}

}  // namespace

std::vector<double> path_errors_m(const RunLog& log, const kin::RobotModel& model) {
  check_joints(log, model);
  const auto kinematics = kin::make_kinematics(model);
  const std::size_t n = log.rows.size();
  std::vector<math::Vec3> pc(n), pm(n);
  for (std::size_t i = 0; i < n; ++i) {
    pc[i] = {log.rows[i].p[0], log.rows[i].p[1], log.rows[i].p[2]};
    pm[i] = kinematics->forward(log.rows[i].measured).p;
  }
  std::vector<double> errors(n);
  for (std::size_t i = 0; i < n; ++i) {
    // The nearest point of the commanded polyline around the sample: a lag along the path is
    // not an error of the path.
    double e = (pm[i] - pc[i]).norm();
    const std::size_t from = i > 600 ? i - 600 : 0, to = std::min(n - 1, i + 50);
    for (std::size_t j = from; j < to; ++j) {
      const math::Vec3 d = pc[j + 1] - pc[j];
      const double len2 = math::dot(d, d);
      const double s = len2 > 0 ? std::clamp(math::dot(pm[i] - pc[j], d) / len2, 0.0, 1.0) : 0.0;
      e = std::min(e, (pc[j] + d * s - pm[i]).norm());
    }
    errors[i] = e;
  }
  return errors;
}

RunPlot run_plot(const RunLog& log, const kin::RobotModel& model) {
  const std::vector<double> errors_m = path_errors_m(log, model);  // checks the joints
  const auto kinematics = kin::make_kinematics(model);
  const std::size_t n = log.rows.size();
  std::vector<double> t(n);
  std::vector<math::Vec3> pc(n), pm(n);
  for (std::size_t i = 0; i < n; ++i) {
    const RunRow& r = log.rows[i];
    t[i] = r.t_s - log.rows.front().t_s;
    pc[i] = {r.p[0], r.p[1], r.p[2]};
    pm[i] = kinematics->forward(r.measured).p;
  }

  // Joints: measured solid, commanded dashed; deg or mm.
  std::vector<Series> joints;
  for (std::size_t j = 0; j < log.dof; ++j) {
    const bool prismatic = model.joints[j].type == kin::JointType::prismatic;
    const double scale = prismatic ? 1e3 : 180.0 / M_PI;
    Series m{t,
             {},
             kColours[j % kColours.size()],
             fmt::format("q{} {}", j + 1, prismatic ? "mm" : "deg")};
    Series c{t, {}, kColours[j % kColours.size()], "", true, 1.0};
    for (const RunRow& r : log.rows) {
      m.y.push_back(r.measured[j] * scale);
      c.y.push_back(r.commanded[j] * scale);
    }
    joints.push_back(std::move(c));
    joints.push_back(std::move(m));
  }

  // The tool path in the plane of the two coordinates it spans most.
  std::array<double, 3> lo{}, hi{};
  for (int k = 0; k < 3; ++k) {
    lo[k] = std::numeric_limits<double>::infinity();
    hi[k] = -lo[k];
  }
  for (const math::Vec3& p : pc) {
    const double v[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], v[k]), hi[k] = std::max(hi[k], v[k]);
  }
  std::array<int, 3> order = {0, 1, 2};
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return hi[a] - lo[a] > hi[b] - lo[b]; });
  int u = std::min(order[0], order[1]), v = std::max(order[0], order[1]);
  const char* names = "xyz";
  const auto coord = [](const math::Vec3& p, int k) { return k == 0 ? p.x : (k == 1 ? p.y : p.z); };
  Series path_c{{}, {}, "#2070c0", "commanded", false, 1.6};
  Series path_m{{}, {}, "#d08020", "measured", true, 1.2};
  for (std::size_t i = 0; i < n; ++i) {
    path_c.x.push_back(coord(pc[i], u) * 1e3);
    path_c.y.push_back(coord(pc[i], v) * 1e3);
    path_m.x.push_back(coord(pm[i], u) * 1e3);
    path_m.y.push_back(coord(pm[i], v) * 1e3);
  }

  // Speed along the path and the path error.
  Series speed_c{t, {}, "#2070c0", "commanded"}, speed_m{t, {}, "#d08020", "measured", true};
  Series error{t, {}, "#c03030", "measured tool from the commanded path"};
  double worst_m = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dt = i == 0 ? 0.0 : log.rows[i].t_s - log.rows[i - 1].t_s;
    speed_c.y.push_back(i == 0 ? 0.0 : (pc[i] - pc[i - 1]).norm() / dt * 1e3);
    speed_m.y.push_back(i == 0 ? 0.0 : (pm[i] - pm[i - 1]).norm() / dt * 1e3);
    error.y.push_back(errors_m[i] * 1e3);
    worst_m = std::max(worst_m, errors_m[i]);
  }

  RunPlot plot;
  plot.robot_title = model.title.empty() ? model.name : model.title;
  plot.samples = n;
  plot.duration_s = t.back();
  plot.worst_path_error_m = worst_m;
  plot.panels = {
      {"Joints (measured solid, commanded dashed)", "t s", "deg / mm", std::move(joints)},
      {fmt::format("Tool path in the {}-{} plane", names[u], names[v]),
       fmt::format("{} mm", names[u]),
       fmt::format("{} mm", names[v]),
       {std::move(path_c), std::move(path_m)},
       true},
      {"Speed along the path", "t s", "mm/s", {std::move(speed_c), std::move(speed_m)}},
      {"Path error (measured tool from the commanded path)", "t s", "mm", {std::move(error)}}};
  return plot;
}

std::string plot_svg(const RunLog& log, const kin::RobotModel& model, const std::string& title) {
  const RunPlot plot = run_plot(log, model);
  constexpr double W = 1200, H = 900;
  std::string svg = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} "
      "{1}\" font-family=\"sans-serif\">\n<style>.title{{font-size:15px;font-weight:bold;"
      "text-anchor:middle}}.tick{{font-size:11px;fill:#444;text-anchor:middle}}.label{{font-size:"
      "12px;text-anchor:middle}}.legend{{font-size:11px}}.frame{{fill:none;stroke:#888}}.grid{{"
      "stroke:#e4e4e4}}</style>\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
      "<text x=\"{2}\" y=\"24\" class=\"title\" style=\"font-size:17px\">{3}</text>\n"
      "<text x=\"{2}\" y=\"42\" class=\"tick\">{4}: {5} samples, {6:.2f} s; worst path error "
      "{7:.3f} mm (measured tool from the commanded path, every sample)</text>\n",
      W, H, W / 2, escape(title), escape(plot.robot_title), plot.samples, plot.duration_s,
      plot.worst_path_error_m * 1e3);
  const double top = 50, ph = (H - top) / 2, pw = W / 2;
  const Box boxes[4] = {
      {0, top, pw, ph}, {pw, top, pw, ph}, {0, top + ph, pw, ph}, {pw, top + ph, pw, ph}};
  for (std::size_t k = 0; k < plot.panels.size(); ++k) panel(svg, boxes[k], plot.panels[k]);
  svg += "</svg>\n";
  return svg;
}

}  // namespace rccx::view
