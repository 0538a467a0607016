#include "plot_command.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <memory>
#include <string>

#include "rccx/io/file.hpp"
#ifdef RCCX_HAVE_RSVG
#include "plot_png.hpp"
#endif
#include "rccx/view/plot.hpp"
#include "rccx/view/run_log.hpp"

namespace rccx::tools {

namespace {

struct PlotArgs {
  RobotChoice robot{"microbo"};
  bool robot_given = false;  ///< --robot or --robot-file: then it must be the log's own
  std::string log;
  std::string out;
  std::string title;
};

int run_plot(const PlotArgs& a) {
  const std::filesystem::path out(a.out);
  std::string ext = out.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  // The format is the file name's: refused before the log is read, so nothing is half done.
  if (ext != ".svg" && ext != ".png") {
    throw BadArgument{
        fmt::format("-o {}: rccx plot writes SVG or PNG; name the file *.svg or *.png", a.out)};
  }
#ifndef RCCX_HAVE_RSVG
  if (ext == ".png") {
    throw BadArgument{fmt::format(
        "-o {}: this rccx was built without PNG output (librsvg was not found when it was "
        "configured): install librsvg2-dev (scripts/install-deps does) and configure the build "
        "again, or write SVG (-o FILE.svg)",
        a.out)};
  }
#endif
  view::RunLog log;
  std::string svg;
  kin::RobotModel model;
  double worst_m = 0.0;
  try {
    log = view::load_run_log(a.log);
    model = robot_of_log(log, a.robot, a.robot_given);
    for (double e : view::path_errors_m(log, model)) worst_m = std::max(worst_m, e);
    svg = view::plot_svg(
        log, model, a.title.empty() ? std::filesystem::path(a.log).filename().string() : a.title);
  } catch (const view::RunLogError& e) {
    throw BadArgument{e.what()};
  }
  io::AtomicFile file(out);
#ifdef RCCX_HAVE_RSVG
  file.write(ext == ".png" ? svg_to_png(svg) : svg);
#else
  file.write(svg);
#endif
  file.commit();
  fmt::print(
      "{}: robot {} ({}), {} samples, {:.2f} s, worst path error {:.3f} mm (measured tool from "
      "the commanded path, every sample) -> {}\n",
      a.log, log.header ? log.header->name : model.name, model.name, log.rows.size(),
      log.rows.back().t_s - log.rows.front().t_s, worst_m * 1e3, a.out);
  return kOk;
}

}  // namespace

void add_plot_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<PlotArgs>();
  CLI::App* cmd = app.add_subcommand(
      "plot",
      "Plot a recorded run (a CSV written by --log or RCCX_LOG) as an SVG or a PNG (the file "
      "name's extension says which; 1200 x 900 px), without a browser: the joints, the tool "
      "path in the plane it moves in most, the speed along the path and the path error (the "
      "measured tool from the commanded path).");
  cmd->add_option("log", args->log, "The run: a CSV rccx wrote (--log FILE, RCCX_LOG=FILE)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->out, "The file to write, *.svg or *.png (replaced whole)")
      ->required()
      ->check(not_empty());
  add_robot_options(*cmd, args->robot);
  cmd->add_option("--title", args->title, "The heading (default: the log's file name)");
  cmd->footer(
      "The log's header names its robot: it is drawn as that robot. --robot / --robot-file are "
      "needed only for a log without a header (rccx before 0.1.0's headers) and are refused "
      "(exit 2) when they name another robot than the header.");
  cmd->callback([args, cmd, &exit_code] {
    args->robot_given = robot_given(*cmd);
    guarded(exit_code, [&] { return run_plot(*args); });
  });
}

}  // namespace rccx::tools
