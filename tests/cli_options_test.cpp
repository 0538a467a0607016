// The rules every rccx option follows, checked over the whole command tree (tools/cli_tree.hpp):
// --help on every command and verb, one duration rule for every duration option (the table
// below must name each one the tree has), bash completion from the tree, report's times.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cli_tree.hpp"
#include "rccx/io/spelling.hpp"
#include "shell_run.hpp"

namespace {

namespace fs = std::filesystem;
using rccx::test::rccx_run;
using rccx::test::ShellRun;

/// Every command of the tree, as typed ("kin fk"), with its options' long names.
void walk(const CLI::App* app, const std::string& path,
          const std::function<void(const std::string&, const CLI::App*)>& visit) {
  visit(path, app);
  for (const CLI::App* s : app->get_subcommands([](const CLI::App*) { return true; })) {
    if (s->get_name().empty()) continue;
    walk(s, path.empty() ? s->get_name() : path + " " + s->get_name(), visit);
  }
}

std::unique_ptr<CLI::App> tree() {
  static int exit_code = 0;
  return rccx::tools::make_app(exit_code);
}

TEST(CliOptions, EveryCommandAndVerbHasHelp) {
  std::size_t commands = 0;
  walk(tree().get(), "", [&](const std::string& path, const CLI::App*) {
    const ShellRun r = rccx_run(path + " --help");
    EXPECT_EQ(r.exit_code, 0) << path << "\n" << r.out;
    EXPECT_NE(r.out.find("Usage"), std::string::npos) << path << "\n" << r.out;
    EXPECT_NE(r.out.find("--help"), std::string::npos) << path;
    ++commands;
  });
  EXPECT_GT(commands, 20U);  // the walk reached the verbs
}

/// A duration option and a command line that runs it briefly with the value at {}.
struct DurationRow {
  std::string command;  ///< the command it belongs to, as the tree names it
  std::string option;
  std::string line;     ///< arguments with {} for the value
  std::string seconds;  ///< a value within its range, in seconds (bare)
};

/// rccx serve of the CVaRL cell's PUMA on loopback, its options to follow.
const std::string kServe = "serve --cell " + std::string(RCCX_ROBOTS_DIR) +
                           "/../cells/cvarl.json --robots puma --interface lo ";

// Every duration option of every command: units everywhere, a bare number is seconds.
const std::vector<DurationRow> kDurations = {
    {"report", "--seconds", "report --seconds {}", "0.2"},
    {"report", "--every", "report --seconds 0.2 --every {}", "0.1"},
    {"report", "--period", "report --robot puma560 --seconds 0.1 --period {}", "0.01"},
    {"calib", "--timeout", "calib --robot puma560 --timeout {}", "60"},
    {"calib", "--period", "calib --robot puma560 --period {}", "0.01"},
    {"limp", "--period", "limp --robot puma560 --period {}", "0.01"},
    {"marsh", "--seconds", "marsh --robot puma560 --seconds {}", "0.2"},
    {"marsh", "--every", "marsh --robot puma560 --seconds 0.2 --every {}", "0.1"},
    {"marsh", "--period", "marsh --robot puma560 --seconds 0.1 --period {}", "0.01"},
    {"jointtest", "--period", "jointtest --robot puma560 --period {} < /dev/null", "0.01"},
    {"cell-load", "--period", "cell-load --robots 1 --seconds 0.05 --period {}", "0.002"},
    {"cell-load", "--seconds", "cell-load --robots 1 --seconds {}", "0.05"},
    {"cell-load", "--spin", "cell-load --robots 1 --seconds 0.05 --spin {}", "0.00001"},
    {"db", "--wait", "db --db /nonexistent/x.db --wait {} list", "0.2"},
    {"view", "--seconds", "view --robot puma560 --port 0 --fast --seconds {}", "0.2"},
    // rccx serve on loopback, each row on a DDS domain no other test uses (45 .. 47).
    {"serve", "--seconds", kServe + "--domain 45 --claim-wait 0.05 --seconds {}", "0.2"},
    {"serve", "--detection", kServe + "--domain 46 --seconds 0.2 --detection {}", "0.1"},
    {"serve", "--claim-wait", kServe + "--domain 47 --seconds 0.2 --claim-wait {}", "0.05"},
};

TEST(CliOptions, TheDurationTableNamesEveryDurationOption) {
  std::set<std::string> in_tree;
  walk(tree().get(), "", [&](const std::string& path, const CLI::App* app) {
    for (const CLI::Option* o : app->get_options()) {
      if (o->get_type_name() == "DURATION") in_tree.insert(path + " " + o->get_name());
    }
  });
  std::set<std::string> in_table;
  for (const DurationRow& d : kDurations) in_table.insert(d.command + " " + d.option);
  EXPECT_EQ(in_tree, in_table);
}

TEST(CliOptions, EveryDurationOptionTakesUnitsAndReadsABareNumberAsSeconds) {
  for (const DurationRow& d : kDurations) {
    const double s = std::stod(d.seconds);
    const std::string line = "timeout -k 5 60 " + std::string(RCCX_CLI) + " " + d.line;
    const auto with = [&](const std::string& value) {
      return rccx::test::run_shell(fmt::format(fmt::runtime(line), value) + " 2>&1");
    };
    // The same duration written five ways is accepted alike (db's file does not exist: 1).
    const int ok = d.command == "db" ? 1 : 0;
    for (const std::string& v : {d.seconds, d.seconds + "s", fmt::format("{:g}ms", s * 1e3),
                                 fmt::format("{:g}us", s * 1e6), fmt::format("{:g}ns", s * 1e9)}) {
      const ShellRun r = with(v);
      EXPECT_EQ(r.exit_code, ok) << d.line << " with " << v << "\n" << r.out;
    }
    const std::string what = d.option + ":";
    for (const auto& [v, says] :
         std::vector<std::pair<std::string, std::string>>{{d.seconds + "x", "is not a duration"},
                                                          {"-" + d.seconds + "s", "out of range"},
                                                          {"''", "\"\" is empty"},
                                                          {"5h", "is not a duration"},
                                                          {"1e400s", "out of range"}}) {
      const ShellRun r = with(v);
      EXPECT_EQ(r.exit_code, 2) << d.line << " with " << v << "\n" << r.out;
      EXPECT_NE(r.out.find(what), std::string::npos) << d.line << " with " << v << "\n" << r.out;
      EXPECT_NE(r.out.find(says), std::string::npos) << d.line << " with " << v << "\n" << r.out;
    }
  }
  // A bare number is seconds everywhere: 28 is refused as a period, and said how to write ms.
  const ShellRun r = rccx_run("report --period 28");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("a bare number is seconds; for milliseconds write 28ms"), std::string::npos)
      << r.out;
}

/// The t of every report line ("t    0.112 s ...").
std::vector<double> report_times(const std::string& out) {
  std::vector<double> times;
  std::istringstream in(out);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("t ", 0) == 0) times.push_back(std::stod(line.substr(2)));
  }
  return times;
}

TEST(CliOptions, ReportRunsForSecondsWhateverEvery) {
  const double period = 0.028;  // the Microbo's
  ShellRun r = rccx_run("report --seconds 0.1", false);
  std::vector<double> t = report_times(r.out);
  ASSERT_EQ(t.size(), 1U) << r.out;
  EXPECT_NEAR(t.back(), 0.1, period / 2) << "the nearest sample to 0.1 s";

  r = rccx_run("report --seconds 1 --every 5", false);  // the run is 1 s, one report at its end
  t = report_times(r.out);
  ASSERT_EQ(t.size(), 1U) << r.out;
  EXPECT_NEAR(t.back(), 1.0, period / 2);

  r = rccx_run("report --seconds 30 --every 0.5", false);  // the waits' rounding does not add up
  t = report_times(r.out);
  ASSERT_EQ(t.size(), 60U) << r.out;
  EXPECT_NEAR(t.back(), 30.0, period / 2);
  for (std::size_t i = 0; i < t.size(); ++i)
    EXPECT_NEAR(t[i], 0.5 * static_cast<double>(i + 1), period / 2) << i;

  const auto start = std::chrono::steady_clock::now();
  r = rccx_run("report --robot puma560 --realtime --period 10ms --seconds 1 --every 5");
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // A machine that stalls may overrun a real-time period: the report restarts control, says so
  // and ends with 1. The option is judged either way.
  const bool overran = r.out.find("control was restarted") != std::string::npos;
  EXPECT_EQ(r.exit_code, overran ? 1 : 0) << r.out;
  EXPECT_LT(wall, 3.0) << "an interval longer than the run must not extend it\n" << r.out;
  ASSERT_FALSE(report_times(r.out).empty()) << r.out;
  EXPECT_NEAR(report_times(r.out).back(), 1.0, 0.05) << r.out;

  r = rccx_run("report --json");
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("add --realtime"), std::string::npos) << r.out;
}

TEST(CliOptions, ARobotFileWhoseBusFitsNoPeriodSaysSoAndAdvicesAPeriodThatIsAccepted) {
  std::ifstream in(fs::path(RCCX_ROBOTS_DIR) / "microbo.json");
  std::stringstream text;
  text << in.rdbuf();
  const std::string microbo = text.str();
  const fs::path dir = fs::temp_directory_path() / ("rccx-bus-" + std::to_string(getpid()));
  fs::create_directories(dir);
  const auto with_exchange = [&](const std::string& us, const std::string& name) {
    std::string s = microbo;
    const std::string key = "\"exchange_us\": 75";
    s.replace(s.find(key), key.size(), "\"exchange_us\": " + us);
    std::ofstream(dir / name) << s;
    return (dir / name).string();
  };
  // 5 ms an exchange: no period RTC serves can carry a sample's traffic.
  const std::string slow = with_exchange("5000", "slow.json");
  ShellRun r = rccx_run("report --seconds 0.1 --robot-file " + slow);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("no period can serve it"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("exchange_us"), std::string::npos) << r.out;
  // 200 us: more than 28 ms, within 56 ms; the period it advises is accepted.
  const std::string slower = with_exchange("200", "slower.json");
  r = rccx_run("report --seconds 0.1 --robot-file " + slower);
  EXPECT_EQ(r.exit_code, 2) << r.out;
  const auto from = r.out.find("choose a period from ");
  ASSERT_NE(from, std::string::npos) << r.out;
  const double advised = std::stod(r.out.substr(from + 21));
  r = rccx_run(fmt::format("report --seconds 0.1 --robot-file {} --period {}ms", slower, advised));
  EXPECT_EQ(r.exit_code, 0) << advised << "\n" << r.out;
  fs::remove_all(dir);
}

TEST(CliOptions, ADatabaseOptionGoesBeforeOrAfterTheVerb) {
  const fs::path db = fs::temp_directory_path() / ("rccx-pos-" + std::to_string(getpid()) + ".db");
  ShellRun r = rccx_run(fmt::format(
      "db put --robot microbo P1 --T 1,0,0,0.325,0,-1,0,0.15,0,0,-1,0.25 --db {}", db.string()));
  ASSERT_EQ(r.exit_code, 0) << r.out;
  for (const char* line : {"db --db {} list", "db list --db {}", "db --robot microbo --db {} list",
                           "db --db {} --wait 2s list --robot microbo"}) {
    r = rccx_run(fmt::format(fmt::runtime(line), db.string()));
    EXPECT_EQ(r.exit_code, 0) << line << "\n" << r.out;
    EXPECT_NE(r.out.find("P1"), std::string::npos) << line << "\n" << r.out;
  }
  fs::remove(db);
}

/// COMPREPLY of the generated completion for the words typed so far (the last is the one
/// being completed).
std::string complete(const std::string& words) {
  const std::string script = fmt::format(
      "source <({} completion bash) && COMP_WORDS=({}) && COMP_CWORD=$((${{#COMP_WORDS[@]}} - 1)) "
      "&& _rccx && echo \"${{COMPREPLY[*]}}\"",
      RCCX_CLI, words);
  std::string quoted;
  for (const char c : script) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  ShellRun r = rccx::test::run_shell("bash -c '" + quoted + "' 2>&1");
  EXPECT_EQ(r.exit_code, 0) << words << "\n" << r.out;
  while (!r.out.empty() && r.out.back() == '\n') r.out.pop_back();
  return r.out;
}

TEST(CliOptions, BashCompletionComesFromTheCommandsOwnDefinition) {
  EXPECT_EQ(complete("rccx re"), "report");
  EXPECT_EQ(complete("rccx report --se"), "--seconds");
  EXPECT_EQ(complete("rccx db list --ro"), "--robot");          // a verb's option
  EXPECT_EQ(complete("rccx db list --d"), "--db");              // its parent's, after the verb
  EXPECT_EQ(complete("rccx db --db x.db li"), "list");          // a value is not a command
  EXPECT_EQ(complete("rccx kin fk --robot puma5"), "puma560");  // known values
  EXPECT_EQ(complete("rccx kin ''"), "fk ik robots");
}

TEST(CliOptions, NearestWordIsATypoOfIt) {
  using rccx::tools::nearest;
  EXPECT_EQ(rccx::io::edit_distance("rprt", "report"), 2U);
  EXPECT_EQ(nearest("rprt", {"report", "rcu", "calib"}), "report");
  EXPECT_EQ(nearest("fx", {"fk", "ik", "robots"}), "fk");
  EXPECT_EQ(nearest("--secnds", {"--seconds", "--every"}), "--seconds");
  EXPECT_EQ(nearest("--sec", {"--seconds", "--every"}), "--seconds");
  EXPECT_EQ(nearest("xyzzy", {"fk", "ik", "robots"}), "");
}

}  // namespace
