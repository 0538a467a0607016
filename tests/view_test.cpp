// rccx::view: the server's HTTP and WebSocket answers, bad input (logs that are not rccx's CSV,
// a port in use, an unknown robot's page while the server goes on), the tap's decimation, the
// SVG plots, and `rccx view` / `rccx plot` on the command line.
#include <gtest/gtest.h>

#include <utility>  // before Boost.Asio 1.74 (std::exchange)

#include <fmt/format.h>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "rccx/cell/cell.hpp"
#include "rccx/io/file.hpp"
#include "rccx/kinematics/kinematics.hpp"
#include "rccx/rccl/manipulator.hpp"
#include "rccx/rtc/simulated_robot.hpp"
#include "rccx/view/plot.hpp"
#include "rccx/view/run_log.hpp"
#include "rccx/view/server.hpp"
#include "shell_run.hpp"

#ifdef RCCX_HAVE_RSVG
#include <cairo.h>
#endif

namespace {

using namespace rccx;
namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using json = nlohmann::json;
using namespace std::chrono_literals;

struct Reply {
  int status = 0;
  std::string body;
  std::string type;
};

Reply request(std::uint16_t port, const std::string& target, http::verb verb = http::verb::get) {
  asio::io_context io;
  beast::tcp_stream stream(io);
  stream.expires_after(5s);
  stream.connect(tcp::endpoint(asio::ip::make_address("127.0.0.1"), port));
  http::request<http::string_body> req(verb, target, 11);
  req.set(http::field::host, "127.0.0.1");
  http::write(stream, req);
  beast::flat_buffer buffer;
  http::response<http::string_body> res;
  http::read(stream, buffer, res);
  beast::error_code ec;
  stream.socket().shutdown(tcp::socket::shutdown_both, ec);
  return {static_cast<int>(res.result_int()), res.body(),
          std::string(res[http::field::content_type])};
}

/// The page's folder: a stand-in index.html (the real bundle is the end-to-end test's).
std::filesystem::path assets_dir() {
  const auto dir = std::filesystem::temp_directory_path() / "rccx_view_test_assets";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "index.html") << "<!doctype html><title>rccx view</title>";
  std::ofstream(dir / "app.js") << "console.log('rccx');";
  return dir;
}

view::ServeOptions quiet() {
  view::ServeOptions o;
  o.announce = false;
  o.assets = assets_dir();
  return o;
}

/// A simulated PUMA in simulated time moving its first joint, with the view on any free port.
struct Live {
  rtc::SimulatedRobot robot{kin::builtin_robot("puma560")};
  rccl::Manipulator arm{*robot.session};
  std::unique_ptr<view::Server> server;

  Live() {
    server = view::serve(*robot.session, 0, quiet());
    arm.start();
    kin::JointVector q = robot.model.ready();
    q[0] += 0.3;
    arm.move(rccl::Position::joints("A", q));
    robot.session->wait_for(1s);  // 100 samples at 10 ms; the tap keeps every other one (50 Hz)
    std::this_thread::sleep_for(150ms);  // the server thread drains every 20 ms
  }
};

TEST(ViewServer, ServesThePageTheSceneAndTheSession) {
  Live live;
  const std::uint16_t port = live.server->port();
  ASSERT_NE(port, 0);
  EXPECT_EQ(live.server->url(), fmt::format("http://127.0.0.1:{}/", port));

  const Reply page = request(port, "/");
  EXPECT_EQ(page.status, 200);
  EXPECT_NE(page.body.find("rccx view"), std::string::npos);
  EXPECT_EQ(page.type, "text/html; charset=utf-8");
  EXPECT_EQ(request(port, "/robot/puma560").status, 200);
  EXPECT_EQ(request(port, "/assets/app.js").type, "text/javascript; charset=utf-8");
  EXPECT_EQ(request(port, "/assets/..%2Fsecret").status, 404);

  const json scene = json::parse(request(port, "/api/scene").body);
  ASSERT_EQ(scene["robots"].size(), 1U);
  EXPECT_EQ(scene["robots"][0]["name"], "puma560");
  EXPECT_EQ(scene["robots"][0]["joints"].size(), 6U);
  EXPECT_DOUBLE_EQ(scene["robots"][0]["joints"][1]["a"].get<double>(),
                   live.robot.model.joints[1].dh.a_m);
  EXPECT_EQ(scene["mode"], "live");

  // The last sample the server has is the session's, decimated to 50 Hz of sample time.
  const json state = json::parse(request(port, "/api/state").body);
  ASSERT_EQ(state["robots"].size(), 1U);
  const json& latest = state["robots"][0];
  const rtc::How how = live.robot.session->how();
  EXPECT_NEAR(latest["t"].get<double>(), how.time_s, 0.02 + 1e-9);
  EXPECT_NEAR(latest["qm"][0].get<double>(), how.joint[0].q, 0.02);
  const view::ServerStats st = live.server->stats();
  EXPECT_GE(st.samples_sent, 45U);
  EXPECT_LE(st.samples_sent, 55U);
  EXPECT_EQ(st.samples_dropped, 0U);
  // A sample by its time.
  const Reply at =
      request(port, fmt::format("/api/state?robot=puma560&t={}", latest["t"].get<double>()));
  EXPECT_EQ(at.status, 200);
  EXPECT_EQ(json::parse(at.body)["q"], latest["q"]);
}

TEST(ViewServer, WebSocketSendsHistoryThenLiveSamples) {
  Live live;
  asio::io_context io;
  websocket::stream<beast::tcp_stream> ws(io);
  beast::get_lowest_layer(ws).expires_after(10s);
  beast::get_lowest_layer(ws).connect(
      tcp::endpoint(asio::ip::make_address("127.0.0.1"), live.server->port()));
  ws.handshake("127.0.0.1", "/ws?robot=puma560");
  beast::flat_buffer buffer;
  ws.read(buffer);
  EXPECT_EQ(json::parse(beast::buffers_to_string(buffer.data()))["type"], "hello");
  buffer.clear();
  ws.read(buffer);
  const json history = json::parse(beast::buffers_to_string(buffer.data()));
  EXPECT_EQ(history["type"], "frames");
  EXPECT_TRUE(history["history"].get<bool>());
  EXPECT_GE(history["frames"].size(), 3U);  // simulated time: a few a server tick
  EXPECT_EQ(history["frames"][0]["q"].size(), 6U);
  EXPECT_EQ(history["frames"][0]["p"].size(), 3U);

  // New samples arrive as the robot moves on.
  live.robot.session->wait_for(200ms);
  buffer.clear();
  ws.read(buffer);
  const json more = json::parse(beast::buffers_to_string(buffer.data()));
  ASSERT_FALSE(more["frames"].empty());
  EXPECT_GT(more["frames"][0]["t"].get<double>(), history["frames"].back()["t"].get<double>());
  EXPECT_EQ(live.server->stats().pages, 1U);
  ws.close(websocket::close_code::normal);
}

TEST(ViewServer, UnknownRobotIsA404AndTheServerGoesOn) {
  Live live;
  const std::uint16_t port = live.server->port();
  const Reply page = request(port, "/robot/nope");
  EXPECT_EQ(page.status, 404);
  EXPECT_NE(page.body.find("no robot &quot;nope&quot; here; the robots are: puma560"),
            std::string::npos)
      << page.body;
  const Reply api = request(port, "/api/scene?robot=nope");
  EXPECT_EQ(api.status, 404);
  EXPECT_EQ(json::parse(api.body)["error"], "no robot \"nope\" here; the robots are: puma560");
  EXPECT_EQ(request(port, "/ws?robot=nope").status, 404);
  EXPECT_EQ(request(port, "/nothing").status, 404);
  EXPECT_EQ(request(port, "/api/log").status, 404);  // live, not a replay
  // Still serving.
  EXPECT_EQ(request(port, "/api/scene").status, 200);
  EXPECT_EQ(request(port, "/").status, 200);
}

TEST(ViewServer, IsReadOnly) {
  Live live;
  for (http::verb v : {http::verb::post, http::verb::put, http::verb::delete_}) {
    const Reply r = request(live.server->port(), "/api/state", v);
    EXPECT_EQ(r.status, 405);
    EXPECT_NE(r.body.find("read-only"), std::string::npos);
  }
}

TEST(ViewServer, PortInUseSaysWhatToDo) {
  view::Server first(view::Scene::of_robot(kin::builtin_robot("microbo")), 0, quiet());
  try {
    view::Server second(view::Scene::of_robot(kin::builtin_robot("microbo")), first.port(),
                        quiet());
    FAIL() << "a second server on the same port";
  } catch (const view::ViewError& e) {
    EXPECT_NE(
        std::string(e.what()).find(fmt::format("port {} on 127.0.0.1 is in use", first.port())),
        std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("--port 0"), std::string::npos);
  }
  EXPECT_EQ(request(first.port(), "/").status, 200);  // the first goes on
  view::ServeOptions bad = quiet();
  bad.address = "localhost:80";
  EXPECT_THROW(view::Server(view::Scene::of_robot(kin::builtin_robot("microbo")), 0, bad),
               view::ViewError);
}

TEST(ViewServer, DetachesFromTheSessionWhileItRuns) {
  rtc::SimulatedRobotOptions options;
  options.clock = rtc::ClockKind::real_time;
  options.period = 20ms;  // room for a loaded machine (sanitizers, CI builds beside)
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"), options);
  rccl::Manipulator arm(*robot.session);
  arm.start();
  for (int i = 0; i < 5; ++i) {
    auto server = view::serve(*robot.session, 0, quiet());
    std::this_thread::sleep_for(60ms);
  }  // each destroyed while the loop calls its tap
  // What must hold: no crash or race (ASan, TSan) and no end of control for any reason but a
  // real-time overrun, which a loaded machine may cause whatever the view does.
  if (!robot.session->controlling()) {
    EXPECT_EQ(robot.session->termination().code, rtc::TerminateCode::overrun)
        << rtc::to_string(robot.session->termination().code);
  }
}

/// The frame of `scene` named `name`, or null.
const json* frame_named(const json& scene, const std::string& name) {
  for (const json& f : scene["frames"]) {
    if (f["name"] == name) return &f;
  }
  return nullptr;
}

/// The position part of a transform as the page takes it (column-major 4 x 4).
math::Vec3 position_of(const json& pose) {
  return {pose[12].get<double>(), pose[13].get<double>(), pose[14].get<double>()};
}

TEST(ViewServer, ShowsTheGoalOfEachMoveOfAnAttachedArmWithoutShow) {
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"));
  rccl::Manipulator arm(*robot.session);
  auto server = view::serve(arm, 0, quiet());
  const std::uint16_t port = server->port();
  arm.start();
  arm.set_velocity(0.05, 0.3);  // slow enough that each motion is seen running
  const auto kinematics = kin::make_kinematics(robot.model);
  kin::JointVector qa = robot.model.ready();
  qa[0] += 0.3;
  kin::JointVector qb = qa;
  qb[0] -= 0.3;
  qb[4] += 0.2;
  const math::Transform tb = kinematics->forward(qb);
  const auto t6 = rccl::t6();
  const auto a = rccl::Position::joints("A", qa);
  const auto b = rccl::Position::make("B", {t6}, {rccl::constant("GB", tb)}, t6);
  EXPECT_TRUE(json::parse(request(port, "/api/scene").body)["frames"].empty());

  const rccl::Motion ma = arm.move(a);
  const rccl::Motion mb = arm.move(b);
  json scene = json::parse(request(port, "/api/scene").body);
  EXPECT_EQ(scene["frames"].size(), 2U) << scene["frames"].dump();
  const json* fa = frame_named(scene, "A");
  const json* fb = frame_named(scene, "B");
  ASSERT_TRUE(fa != nullptr && fb != nullptr) << scene["frames"].dump();
  EXPECT_EQ((*fa)["robot"], 0);
  EXPECT_LT((position_of((*fa)["pose"]) - kinematics->forward(qa).p).norm(), 1e-9);
  EXPECT_LT((position_of((*fb)["pose"]) - tb.p).norm(), 1e-9);
  EXPECT_NE((*fb)["note"].get<std::string>().find("GB"), std::string::npos) << (*fb)["note"];

  // The samples of each motion name the goal it goes to.
  const auto goal_now = [&] {
    std::this_thread::sleep_for(150ms);  // the server thread drains every 20 ms
    const json latest = json::parse(request(port, "/api/state").body)["robots"][0];
    return latest.value("goal", std::string("(none)"));
  };
  ASSERT_EQ(arm.waitfor(ma.start()), rccl::WaitResult::reached);
  robot.session->wait_for(100ms);
  ASSERT_FALSE(arm.happened(ma.end()));
  EXPECT_EQ(goal_now(), "A");
  ASSERT_EQ(arm.waitfor(mb.start()), rccl::WaitResult::reached);
  robot.session->wait_for(100ms);
  ASSERT_FALSE(arm.happened(mb.end()));
  EXPECT_EQ(goal_now(), "B");
  ASSERT_EQ(arm.waitfor(rccl::Manipulator::completed()), rccl::WaitResult::reached);

  // The same position again is the same frame; a refused move shows nothing.
  arm.move(a);
  kin::JointVector far = qa;
  far[0] = robot.model.joints[0].upper + 1.0;
  EXPECT_THROW(arm.move(rccl::Position::joints("OUT", far)), rccl::MotionError);
  scene = json::parse(request(port, "/api/scene").body);
  EXPECT_EQ(scene["frames"].size(), 2U) << scene["frames"].dump();
  EXPECT_EQ(frame_named(scene, "OUT"), nullptr);

  // The arm may outlive the view: its observer then does nothing.
  server.reset();
  const rccl::Motion again = arm.move(b);
  EXPECT_EQ(arm.waitfor(again.end()), rccl::WaitResult::reached);
}

TEST(ViewServer, ACellShowsEachRobotsGoalsWithoutShow) {
  const auto c = cell::Cell::load(RCCX_CVARL_CELL);
  c->start();
  auto server = view::serve(*c, 0, quiet());
  const std::uint16_t port = server->port();
  std::vector<rccl::Motion> motions;
  std::vector<math::Vec3> goals;
  for (const char* name : {"puma", "microbo"}) {
    rccl::Manipulator& arm = c->robot(name);
    arm.set_velocity(0.05, 0.3);
    kin::JointVector q = arm.kinematics().model().ready();
    q[3] += 0.3;  // a wrist: the arms keep apart
    motions.push_back(arm.move(rccl::Position::joints(fmt::format("{}_GOAL", name), q)));
    goals.push_back((c->base(name) * arm.kinematics().forward(q)).p);
  }
  c->wait_for(100ms);
  std::this_thread::sleep_for(150ms);
  const json scene = json::parse(request(port, "/api/scene").body);
  const json state = json::parse(request(port, "/api/state").body);
  const char* names[] = {"puma", "microbo"};
  for (int r = 0; r < 2; ++r) {
    const std::string goal = fmt::format("{}_GOAL", names[r]);
    const json* f = frame_named(scene, goal);
    ASSERT_NE(f, nullptr) << scene["frames"].dump();
    EXPECT_EQ((*f)["robot"], r);
    EXPECT_LT((position_of((*f)["pose"]) - goals[static_cast<std::size_t>(r)]).norm(), 1e-9);
    ASSERT_FALSE(c->robot(names[r]).happened(motions[static_cast<std::size_t>(r)].end()));
    EXPECT_EQ(state["robots"][r].value("goal", std::string("(none)")), goal);
  }
  // One robot's page lists its own goals, not the other's.
  const json microbo = json::parse(request(port, "/api/scene?robot=microbo").body);
  EXPECT_NE(frame_named(microbo, "microbo_GOAL"), nullptr);
  EXPECT_EQ(frame_named(microbo, "puma_GOAL"), nullptr);
  server.reset();  // before the cell's sessions
}

constexpr const char* kGoodLog =
    "t,seg,q1,q2,qm1,qm2,x,y,z,ax,ay,az\n"
    "0.01,0,0.1,0.2,0.1,0.2,0.5,0,0.3,0,0,-1\n"
    "0.02,1,0.11,0.2,0.1,0.2,0.51,0,0.3,0,0,-1\n";

TEST(RunLog, ReadsWhatSampleLogWrites) {
  const view::RunLog log = view::parse_run_log(kGoodLog, "run.csv");
  EXPECT_EQ(log.dof, 2U);
  ASSERT_EQ(log.rows.size(), 2U);
  EXPECT_DOUBLE_EQ(log.rows[1].commanded[0], 0.11);
  EXPECT_EQ(log.rows[1].segment, 1);
  EXPECT_DOUBLE_EQ(log.rows[1].p[0], 0.51);
}

TEST(RunLog, RefusesOtherFilesNamingLineAndColumn) {
  const auto message = [](std::string_view text) {
    try {
      (void)view::parse_run_log(text, "run.csv");
    } catch (const view::RunLogError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("").find("run.csv: empty"), std::string::npos);
  EXPECT_NE(message("time,x,y\n1,2,3\n")
                .find("run.csv:1: the header \"time,x,y\" is not a log "
                      "rccx writes"),
            std::string::npos);
  EXPECT_NE(message("t,seg,q1,q2,qm1,qm2,x,y,z,ax,ay,bz\n")
                .find("run.csv:1: column 12 is \"bz\", "
                      "expected az"),
            std::string::npos);
  EXPECT_NE(message("t,seg,q1,q2,qm1,qm2,x,y,z,ax,ay,az\n").find("a header and no samples"),
            std::string::npos);
  std::string bad_number = kGoodLog;
  bad_number += "0.03,1,0.11,abc,0.1,0.2,0.51,0,0.3,0,0,-1\n";
  EXPECT_NE(message(bad_number).find("run.csv:4: column 4 (q2)"), std::string::npos)
      << message(bad_number);
  std::string short_row = kGoodLog;
  short_row += "0.03,1,0.11\n";
  EXPECT_NE(message(short_row).find("run.csv:4: 3 columns, the header has 12"), std::string::npos);
  std::string backwards = kGoodLog;
  backwards += "0.015,1,0.11,0.2,0.1,0.2,0.51,0,0.3,0,0,-1\n";
  EXPECT_NE(message(backwards).find("run.csv:4: column 1 (t): time 0.015 does not follow 0.02"),
            std::string::npos);
  std::string nan = kGoodLog;
  nan += "0.03,1,nan,0.2,0.1,0.2,0.51,0,0.3,0,0,-1\n";
  EXPECT_NE(message(nan).find("run.csv:4: column 3 (q1)"), std::string::npos);
}

TEST(RunLog, ReplayRefusesALogOfAnotherRobot) {
  const view::RunLog log = view::parse_run_log(kGoodLog, "run.csv");
  EXPECT_THROW(view::serve_replay(kin::builtin_robot("puma560"), log, 0, quiet()),
               view::RunLogError);
}

/// A recorded run of the PUMA (RCCX_LOG's format, through SampleLog itself) in `file`.
void record_puma_run(const std::filesystem::path& file) {
  rtc::SimulatedRobotOptions options;
  options.log = file;
  rtc::SimulatedRobot robot(kin::builtin_robot("puma560"), options);
  rccl::Manipulator arm(*robot.session);
  arm.start();
  kin::JointVector q = robot.model.ready();
  q[0] += 0.3;
  arm.waitfor(arm.move(rccl::Position::joints("A", q)).end());
  arm.stop_control();
  EXPECT_EQ(robot.finish(), "");
}

TEST(Plot, DrawsTheFourPanels) {
  const auto file = std::filesystem::temp_directory_path() / "rccx_view_test_run.csv";
  record_puma_run(file);
  const view::RunLog log = view::load_run_log(file);
  const std::string svg = view::plot_svg(log, kin::builtin_robot("puma560"), "a <test> run");
  EXPECT_EQ(svg.rfind("<svg", 0), 0U);
  for (const char* part : {"Joints", "Tool path in the", "Speed along the path", "Path error",
                           "a &lt;test&gt; run", "</svg>"}) {
    EXPECT_NE(svg.find(part), std::string::npos) << part;
  }
  EXPECT_GE(std::count(svg.begin(), svg.end(), '\n'), 20);
  EXPECT_THROW((void)view::plot_svg(view::parse_run_log(kGoodLog, "two.csv"),
                                    kin::builtin_robot("puma560"), "x"),
               view::RunLogError);
  std::filesystem::remove(file);
}

TEST(ViewCli, BadInputExitsTwoWithWhatToDo) {
  const auto dir = std::filesystem::temp_directory_path() / "rccx_view_cli_test";
  std::filesystem::create_directories(dir);
  const auto bad = dir / "bad.csv";
  std::ofstream(bad) << "time,x\n1,2\n";
  auto r = test::rccx_run(fmt::format("plot {} -o {}/out.svg", bad.string(), dir.string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.out.find(":1: the header"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.svg"));
  r = test::rccx_run(fmt::format("view --log {} --port 0 --seconds 1", bad.string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.out.find("--log: "), std::string::npos) << r.out;

  std::ofstream(dir / "good.csv") << kGoodLog;
  r = test::rccx_run(fmt::format("plot {}/good.csv -o {}/out.pdf", dir.string(), dir.string()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.out.find("out.pdf: rccx plot writes SVG or PNG; name the file *.svg or *.png"),
            std::string::npos)
      << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "out.pdf"));

  view::Server taken(view::Scene::of_robot(kin::builtin_robot("microbo")), 0, quiet());
  r = test::rccx_run(fmt::format("view --robot microbo --port {} --seconds 1", taken.port()));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.out.find("is in use"), std::string::npos) << r.out;
  std::filesystem::remove_all(dir);
}

TEST(RunLog, TheHeaderNamesTheRobotItIsDrawnAs) {
  const kin::RobotModel puma = kin::builtin_robot("puma560");
  const std::string header =
      rtc::LogHeader::of(puma, "left", std::chrono::milliseconds(10), true).line();
  const view::RunLog headed = view::parse_run_log(header + kGoodLog, "run.csv");
  ASSERT_TRUE(headed.header);
  EXPECT_EQ(headed.header->name, "left");
  EXPECT_EQ(headed.rows.size(), 2U) << "the header line is no row";
  EXPECT_EQ(view::log_robot(headed, nullptr, "").name, "puma560") << "drawn as its own robot";
  EXPECT_EQ(view::log_robot(headed, &puma, "--robot puma560").name, "puma560");
  const kin::RobotModel microbo = kin::builtin_robot("microbo");
  kin::RobotModel bent = puma;  // a robot file that says it is the PUMA, with another link
  bent.joints[2].dh.a_m += 0.01;
  for (const kin::RobotModel* other : {&microbo, static_cast<const kin::RobotModel*>(&bent)}) {
    try {
      (void)view::log_robot(headed, other, "--robot-file x.json");
      ADD_FAILURE() << "a log of the PUMA drawn as " << other->name;
    } catch (const view::RunLogError& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find("robot puma560"), std::string::npos) << m;
      EXPECT_NE(m.find("--robot-file x.json"), std::string::npos) << m;
    }
  }
  // An old log, before headers: only as the robot named for it.
  const view::RunLog old = view::parse_run_log(kGoodLog, "old.csv");
  EXPECT_FALSE(old.header);
  EXPECT_THROW((void)view::log_robot(old, nullptr, ""), view::RunLogError);
  EXPECT_EQ(view::log_robot(old, &microbo, "--robot microbo").name, "microbo");
  // A header that is not whole is refused with its line.
  try {
    (void)view::parse_run_log(std::string("# rccx-log 1 robot=puma560\n") + kGoodLog, "h.csv");
    ADD_FAILURE() << "a header without its kinematics accepted";
  } catch (const view::RunLogError& e) {
    EXPECT_NE(std::string(e.what()).find("h.csv:1: the header line has no valid kinematics="),
              std::string::npos)
        << e.what();
  }
}

TEST(ViewCli, PlotAndReplayDrawALogAsItsOwnRobotAndRefuseAnother) {
  const auto dir = std::filesystem::temp_directory_path() / "rccx_view_cli_robot_test";
  std::filesystem::create_directories(dir);
  const auto run = dir / "run.csv";
  record_puma_run(run);
  const auto svg = (dir / "out.svg").string();
  auto r = test::rccx_run(fmt::format("plot {} -o {}", run.string(), svg));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  EXPECT_NE(r.out.find("robot puma560 (puma560)"), std::string::npos) << r.out;
  std::filesystem::remove(svg);
  for (const std::string& command :
       {fmt::format("plot {} --robot microbo -o {}", run.string(), svg),
        fmt::format("view --log {} --robot microbo --port 0 --seconds 1", run.string())}) {
    r = test::rccx_run(command);
    EXPECT_EQ(r.exit_code, 2) << command << "\n" << r.out;
    EXPECT_NE(r.out.find("is a log of robot puma560"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("not of --robot microbo"), std::string::npos) << r.out;
  }
  EXPECT_FALSE(std::filesystem::exists(svg)) << "a refused plot wrote its file";
  r = test::rccx_run(fmt::format("view --log {} --port 0 --seconds 0.5", run.string()));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  // The same log without its header line (as rccx wrote before headers): --robot is needed.
  std::string text = io::read_file(run);
  io::write_file_atomically(dir / "old.csv", text.substr(text.find('\n') + 1));
  r = test::rccx_run(fmt::format("plot {}/old.csv -o {}", dir.string(), svg));
  EXPECT_EQ(r.exit_code, 2) << r.out;
  EXPECT_NE(r.out.find("no header line naming its robot"), std::string::npos) << r.out;
  r = test::rccx_run(fmt::format("plot {}/old.csv --robot puma560 -o {}", dir.string(), svg));
  EXPECT_EQ(r.exit_code, 0) << r.out;
  std::filesystem::remove_all(dir);
}

/// Big-endian 32 bits at `at` of `s`.
std::uint32_t be32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<unsigned char>(s.at(at + i));
  return v;
}

TEST(ViewCli, PlotWritesPng) {
  const auto dir = std::filesystem::temp_directory_path() / "rccx_view_cli_png_test";
  std::filesystem::create_directories(dir);
  const auto run = dir / "run.csv";
  record_puma_run(run);
  const auto png = dir / "out.png";
  const auto r =
      test::rccx_run(fmt::format("plot {} --robot puma560 -o {}", run.string(), png.string()));
#ifdef RCCX_HAVE_RSVG
  ASSERT_EQ(r.exit_code, 0) << r.out;
  std::ifstream in(png, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_GE(bytes.size(), 33U);
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_EQ(bytes.substr(12, 4), "IHDR");  // the first chunk: width, height
  EXPECT_EQ(be32(bytes, 16), 1200U);
  EXPECT_EQ(be32(bytes, 20), 900U);
  // Decoded, it is a plot: most pixels the white background, some the lines and text.
  cairo_surface_t* image = cairo_image_surface_create_from_png(png.c_str());
  ASSERT_EQ(cairo_surface_status(image), CAIRO_STATUS_SUCCESS);
  // Opaque: cairo writes it as RGB and reads it back as RGB24 (the top byte unused).
  const cairo_format_t format = cairo_image_surface_get_format(image);
  ASSERT_TRUE(format == CAIRO_FORMAT_RGB24 || format == CAIRO_FORMAT_ARGB32) << format;
  const int w = cairo_image_surface_get_width(image), h = cairo_image_surface_get_height(image);
  const int stride = cairo_image_surface_get_stride(image);
  const unsigned char* data = cairo_image_surface_get_data(image);
  std::size_t white = 0, other = 0;
  for (int y = 0; y < h; ++y) {
    const auto* row =
        reinterpret_cast<const std::uint32_t*>(data + static_cast<std::ptrdiff_t>(y) * stride);
    for (int x = 0; x < w; ++x) ((row[x] & 0xffffffU) == 0xffffffU ? white : other)++;
  }
  cairo_surface_destroy(image);
  const double total = static_cast<double>(w) * h;
  EXPECT_GT(static_cast<double>(white) / total, 0.5) << "the background is white";
  EXPECT_GT(static_cast<double>(other) / total, 0.01) << "lines and text are drawn";
#else
  // Built without librsvg: -o FILE.png says how to get it, and writes nothing.
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.out.find("install librsvg2-dev"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(png));
#endif
  std::filesystem::remove_all(dir);
}

}  // namespace
