// The studio in process: the scene's timeline (keyframes, deposits, timed
// elements) as `run` replays it, the session's edits recorded so that the
// saved scene reproduces the session bit for bit, and the web server's
// refusals, limits and frame dropping over real sockets (Boost.Beast clients).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <fstream>
#include <thread>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

#include "gpu/gl_context.h"
#include "run/run_clock.h"
#include "scenes/scene_loader.h"
#include "sim/simulation_factory.h"
#include "studio/studio_server.h"

using namespace morphoflow;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = boost::asio::ip::tcp;

namespace {

// A small coupled scene with smoke, sources and an obstacle: every kind of edit applies to it.
const std::string kScene = R"(
name = "studio_test"
[grid]
resolution = [32, 32]
[domain]
size = [1.0, 1.0]
[time]
dt = 0.01
steps = 1000000
[fluid]
lid_velocity = 1.0
reynolds = 400
[smoke]
buoyancy = 1.0
[[sources]]
center = [0.5, 0.15]
radius = 0.08
density = 1.0
temperature = 1.0
[[obstacles]]
center = [0.3, 0.6]
radius = 0.08
[rd]
model = "gray-scott"
resolution = [64, 64]
diffusion = [2e-5, 1e-5]
[rd.parameters]
F = 0.04
k = 0.06
[rd.initial]
values = [1.0, 0.0]
square = 0.3
square_values = [0.5, 0.25]
[coupling]
rd_time_scale = 50.0
[output]
field = "v"
video = false
)";

const std::string kPath = std::string(MORPHOFLOW_SOURCE_DIR) + "/scenes/studio_test.toml";
const auto quiet = [](const std::string&) {};

// The fields of a simulation, each flattened (the velocity's components one after another).
template <int D>
std::map<std::string, std::vector<float>> fieldsOf(const Simulation<D>& sim) {
  std::map<std::string, std::vector<float>> out;
  for (const std::string& name : sim.fieldNames())
    for (const Grid<float, D>& g : sim.field(name))
      out[name].insert(out[name].end(), g.values().begin(), g.values().end());
  return out;
}

// The float32 values of a .npy file (its header checked).
std::vector<float> npyValues(const std::string& npy) {
  EXPECT_EQ(npy.substr(0, 6), "\x93NUMPY");
  const size_t header = size_t(uint8_t(npy[8])) | size_t(uint8_t(npy[9])) << 8;
  EXPECT_NE(npy.find("'descr': '<f4'"), std::string::npos);
  std::vector<float> v((npy.size() - 10 - header) / 4);
  std::memcpy(v.data(), npy.data() + 10 + header, v.size() * 4);
  return v;
}

// Steps the session until it has taken `steps` steps (paused after).
void stepTo(StudioSession& s, long steps) {
  const long now = s.state()["steps"].get<long>();
  if (steps > now) s.control({{"action", "step"}, {"count", steps - now}});
  for (int k = 0; k < 2000 && s.state()["steps"].get<long>() < steps; ++k)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_EQ(s.state()["steps"].get<long>(), steps);
}

// `run`'s loop over the saved scene (the factory, the clock, one advance at a time) up to `steps`.
std::map<std::string, std::vector<float>> runSaved(const std::string& text, long steps, long* rebuilds = nullptr,
                                                   Backend backend = Backend::TBB) {
  const Scene scene = parseScene(text, kPath);
  std::unique_ptr<Simulation<2>> sim = makeSimulation<2>(scene, backend, quiet, quiet);
  const RunClock clock(runTime(scene));
  while (sim->steps() < steps) sim->advance(clock.dt(*sim), 1);
  if (rebuilds) *rebuilds = dynamic_cast<TimelineSimulation<2>&>(*sim).rebuilds();
  return fieldsOf(*sim);
}

}  // namespace

TEST(Timeline, KeyframesInterpolateByStepOrLinearly) {
  KeyedValue k;
  k.times = {1.0, 3.0};
  k.values = {{10.0}, {30.0}};
  EXPECT_EQ(k.at(0.0)[0], 10.0);  // before the first key: its value
  EXPECT_EQ(k.at(2.0)[0], 10.0);  // step: held until the next key
  EXPECT_EQ(k.at(3.5)[0], 30.0);
  k.linear = true;
  EXPECT_DOUBLE_EQ(k.at(2.0)[0], 20.0);
  EXPECT_DOUBLE_EQ(k.at(2.5)[0], 25.0);
  EXPECT_EQ(k.at(9.0)[0], 30.0);
}

TEST(Timeline, EveryKeyframeValueGoesThroughTheReadersChecksAtItsPlace) {
  try {
    parseScene(kScene + "[rd.keyed]\n", kPath, {"coupling.rd_time_scale={keys=[[0, 50.0], [2, -1.0]]}"});
    FAIL() << "a keyframe out of range was accepted";
  } catch (const UserError& e) {
    EXPECT_EQ(e.key(), "coupling.rd_time_scale");
    EXPECT_NE(std::string(e.what()).find("at t = 2: expected a number in (0, 1e+09], found -1"), std::string::npos)
        << e.what();
  } catch (...) {
  }
  // A structural key takes no keyframes, and says which keys do.
  try {
    parseScene(kScene, kPath, {"rd.resolution={keys=[[0, [64, 64]], [1, [32, 32]]]}"});
    FAIL() << "a keyframed resolution was accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot change during a run"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("rd.parameters.*"), std::string::npos);
  }
  // Times must increase; a deposit names a field the scene has.
  EXPECT_THROW(parseScene(kScene, kPath, {"rd.parameters.F={keys=[[1, 0.04], [1, 0.05]]}"}), UserError);
  EXPECT_THROW(
      parseScene(kScene + "[[deposits]]\nfield = \"w\"\ncenter = [0.5, 0.5]\nradius = 0.1\nvalue = 1.0\n", kPath),
      UserError);
}

TEST(Timeline, KeyframesEnterTheSettingsHashAndAKeyedSceneRebuildsOnlyWhereAValueChanges) {
  const Scene plain = parseScene(kScene, kPath);
  const Scene keyed =
      parseScene(kScene, kPath, {"rd.parameters.F={keys=[[0, 0.04], [0.05, 0.05]], interpolation=\"step\"}"});
  EXPECT_NE(plain.resolvedJson, keyed.resolvedJson);
  EXPECT_TRUE(plain.timeline.empty());
  ASSERT_EQ(keyed.timeline.keyed.size(), 1u);
  std::unique_ptr<Simulation<2>> sim = makeSimulation<2>(keyed, Backend::TBB, quiet, quiet);
  for (int k = 0; k < 10; ++k) sim->step(0.01);
  EXPECT_EQ(dynamic_cast<TimelineSimulation<2>&>(*sim).rebuilds(), 1);
  EXPECT_DOUBLE_EQ(dynamic_cast<TimelineSimulation<2>&>(*sim).current().rd.settings.parameters[0], 0.05);
}

TEST(Timeline, ACheckpointOfATimelineContinuesBitForBit) {
  const Scene scene =
      parseScene(kScene + "[[deposits]]\nt = 0.08\nfield = \"v\"\ncenter = [0.5, 0.5]\nradius = 0.1\nvalue = 0.3\n",
                 kPath, {"rd.parameters.k={keys=[[0, 0.06], [0.05, 0.062], [0.12, 0.058]], interpolation=\"linear\"}"});
  auto whole = makeSimulation<2>(scene, Backend::TBB, quiet, quiet);
  for (int k = 0; k < 16; ++k) whole->step(0.01);
  auto first = makeSimulation<2>(scene, Backend::TBB, quiet, quiet);
  for (int k = 0; k < 7; ++k) first->step(0.01);
  std::string bytes;
  StateWriter w([&](std::string_view frame, const void* data, size_t n) {
    bytes.append(frame);
    bytes.append(static_cast<const char*>(data), n);
  });
  first->save(&w);
  auto second = makeSimulation<2>(scene, Backend::TBB, quiet, quiet);
  second->load(StateReader(std::move(bytes)));
  for (int k = 7; k < 16; ++k) second->step(0.01);
  EXPECT_EQ(fieldsOf(*whole), fieldsOf(*second));
}

// Edits of every kind, at different steps: the saved scene, run by `run`'s
// loop, gives the session's fields bit for bit.
TEST(Studio, TheSavedSceneReplaysTheSessionBitForBit) {
  StudioSession s(kScene, kPath, StudioOptions{});
  s.set({{"rd.parameters.F", 0.045}});  // before the first step: the scene itself changes
  stepTo(s, 4);
  s.set({{"rd.parameters.F", 0.05}, {"rd.diffusion", {2.2e-5, 1.1e-5}}});
  stepTo(s, 7);
  s.paint({{"kind", "deposit"}, {"field", "v"}, {"center", {0.6, 0.6}}, {"radius", 0.1}, {"value", 0.4}});
  stepTo(s, 9);
  s.paint({{"kind", "obstacle"}, {"shape", "box"}, {"center", {0.7, 0.4}}, {"size", {0.1, 0.2}}});
  s.paint({{"kind", "move"}, {"target", "obstacles.1"}, {"center", {0.72, 0.45}}});  // moved as it is added: in place
  stepTo(s, 11);
  s.paint({{"kind", "move"}, {"target", "obstacles.0"}, {"center", {0.25, 0.7}}});
  s.set({{"smoke.vorticity", 0.5}, {"sources.0.density", 2.0}});
  stepTo(s, 13);
  s.paint({{"kind", "source"}, {"center", {0.8, 0.2}}, {"radius", 0.05}, {"density", 1.0}, {"temperature", 2.0}});
  s.paint({{"kind", "stroke"}, {"points", {{0.2, 0.2}, {0.4, 0.3}}}, {"width", 0.02}, {"values", {0.5, 0.25}}});
  stepTo(s, 15);
  s.paint({{"kind", "erase"}, {"target", "obstacles.1"}});
  s.set({{"coupling.rd_time_scale", 80.0}});
  stepTo(s, 18);
  const std::string text = s.sceneText();
  EXPECT_NE(text.find("interpolation = 'step'"), std::string::npos) << text;
  EXPECT_NE(text.find("[[deposits]]"), std::string::npos);

  long rebuilds = 0;
  const auto replay = runSaved(text, 18, &rebuilds);
  EXPECT_GE(rebuilds, 5);
  for (const auto& [name, values] : replay) {
    if (name == "velocity") continue;  // (three grids; u and v checked through speed, vorticity and the species)
    EXPECT_EQ(npyValues(s.fieldNpy(name)), values) << name << " differs";
  }
  // The deposit and the parameter changes did something.
  EXPECT_NE(runSaved(EditLog(kScene, kPath).text(), 18).at("v"), replay.at("v"));
}

// The same on the GPU backend (skipped without a GL context): the studio's
// simulation, built again at each edit, and the saved scene replayed give
// bitwise the same fields. (The studio is closed before the replay: one GL
// simulation at a time.)
TEST(Studio, OnTheGpuTheSavedSceneReplaysTheSessionBitForBit) {
  if (const GpuInfo g = gpuInfo(); !g.available) GTEST_SKIP() << g.reason;
  std::string text;
  std::map<std::string, std::vector<float>> studio;
  {
    StudioOptions gpu;
    gpu.backend = "gpu";
    StudioSession s(kScene, kPath, gpu);
    stepTo(s, 3);
    s.set({{"rd.parameters.F", 0.05}, {"smoke.vorticity", 0.5}});
    stepTo(s, 5);
    s.paint({{"kind", "deposit"}, {"field", "v"}, {"center", {0.6, 0.6}}, {"radius", 0.1}, {"value", 0.4}});
    s.paint({{"kind", "obstacle"}, {"center", {0.7, 0.4}}, {"radius", 0.06}});
    stepTo(s, 7);
    s.paint({{"kind", "move"}, {"target", "obstacles.0"}, {"center", {0.25, 0.7}}});
    stepTo(s, 9);
    text = s.sceneText();
    for (const char* name : {"u", "v", "speed", "dye", "temperature"}) studio[name] = npyValues(s.fieldNpy(name));
  }
  long rebuilds = 0;
  const auto replay = runSaved(text, 9, &rebuilds, Backend::Gpu);
  EXPECT_EQ(rebuilds, 3);
  for (const auto& [name, values] : studio) EXPECT_EQ(replay.at(name), values) << name << " differs";
}

TEST(Studio, ABadEditChangesNothingAndSaysTheReadersMessage) {
  StudioSession s(kScene, kPath, StudioOptions{});
  stepTo(s, 2);
  const std::string before = s.sceneText();
  try {
    s.set({{"rd.parameters.F", 0.05}, {"coupling.rd_time_scale", -2.0}});
    FAIL() << "a negative time scale was accepted";
  } catch (const UserError& e) {
    EXPECT_NE(std::string(e.what()).find("expected a number in (0, 1e+09], found -2"), std::string::npos) << e.what();
  }
  EXPECT_EQ(s.sceneText(), before);  // all or nothing: F is unchanged too
  EXPECT_THROW(s.set({{"grid.resolution", {64, 64}}}), UserError);
  EXPECT_THROW(s.set({{"rd.parameters.F", "much"}}), UserError);
  EXPECT_THROW(s.paint({{"kind", "erase"}, {"target", "obstacles.9"}}), UserError);
  EXPECT_THROW(s.paint({{"kind", "deposit"}, {"field", "v"}, {"center", {5.0, 0.5}}, {"radius", 0.1}, {"value", 1.0}}),
               UserError);
  EXPECT_THROW(s.control({{"action", "explode"}}), UserError);
  EXPECT_THROW(s.fieldNpy("nothing"), UserError);
  EXPECT_EQ(s.sceneText(), before);
  stepTo(s, 4);  // and the simulation goes on
}

// The step of a frame (its JSON header).
long frameStep(const std::shared_ptr<const std::string>& frame) {
  if (!frame || frame->size() < 8) return -1;
  uint32_t n = 0;
  std::memcpy(&n, frame->data() + 4, 4);
  return nlohmann::json::parse(frame->substr(8, n))["step"].get<long>();
}

// A pause shows the step the run stopped at, wherever it lands (during a
// step or between two), though no frame was due while running.
TEST(Studio, APausedRunShowsTheStepItStoppedAt) {
  StudioSession s(kScene, kPath, StudioOptions{});
  s.view({{"steps_per_frame", 10000}});
  auto steps = [&] { return s.state()["steps"].get<long>(); };
  for (int round = 0; round < 8; ++round) {
    const long from = steps();
    s.control({{"action", "play"}});
    for (int k = 0; k < 2000 && steps() < from + 2 + round; ++k)
      std::this_thread::sleep_for(std::chrono::microseconds(500));
    s.control({{"action", "pause"}});
    bool shown = false;
    for (int k = 0; k < 1000 && !shown; ++k) {
      shown = !s.state()["running"].get<bool>() && frameStep(s.frame()) == steps();
      if (!shown) std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    EXPECT_TRUE(shown) << "round " << round << ": the frame shows step " << frameStep(s.frame()) << " of " << steps();
  }
}

TEST(Studio, ResetStartsAgainWithTheEditsAsTheScene) {
  StudioSession s(kScene, kPath, StudioOptions{});
  stepTo(s, 3);
  s.set({{"rd.parameters.F", 0.05}});
  s.paint({{"kind", "obstacle"}, {"center", {0.7, 0.4}}, {"radius", 0.05}});
  stepTo(s, 5);
  s.control({{"action", "reset"}});
  EXPECT_EQ(s.state()["steps"].get<long>(), 0);
  EXPECT_DOUBLE_EQ(s.state()["keys"]["rd.parameters.F"]["value"].get<double>(), 0.05);
  const Scene now = parseScene(s.sceneText(), kPath);
  EXPECT_TRUE(now.timeline.empty());
  EXPECT_EQ(now.fluid.obstacles.size(), 2u);
}

namespace {

struct Client {
  boost::asio::io_context ioc;
  tcp::socket socket{ioc};
  explicit Client(unsigned short port) { socket.connect({boost::asio::ip::make_address("127.0.0.1"), port}); }
  http::response<http::string_body> request(http::verb verb, const std::string& target, const std::string& body,
                                            const std::map<std::string, std::string>& headers) {
    http::request<http::string_body> req{verb, target, 11};
    for (const auto& [k, v] : headers) req.set(k, v);
    req.body() = body;
    req.prepare_payload();
    http::write(socket, req);
    beast::flat_buffer buffer;
    http::response<http::string_body> res;
    http::read(socket, buffer, res);
    return res;
  }
};

struct Served {
  StudioServer server;
  std::map<std::string, std::string> ok;
  Served() : server(ServerOptions{}, StudioOptions{}, kScene, kPath, std::string(MORPHOFLOW_SOURCE_DIR) + "/scenes") {
    ok = {{"Host", "127.0.0.1:" + std::to_string(server.port())}, {"Authorization", "Bearer " + server.token()}};
  }
  http::response<http::string_body> call(http::verb verb, const std::string& target, const std::string& body = {},
                                         std::map<std::string, std::string> headers = {}) {
    for (const auto& [k, v] : ok) headers.emplace(k, v);
    Client c(server.port());
    return c.request(verb, target, body, headers);
  }
};

}  // namespace

TEST(StudioServer, RefusesRequestsWithoutTheTokenOrFromAnotherSite) {
  Served s;
  EXPECT_EQ(s.server.url().rfind("http://127.0.0.1:", 0), 0u);
  EXPECT_NE(s.server.url().find("?token=" + s.server.token()), std::string::npos);
  EXPECT_GE(s.server.token().size(), 32u);
  EXPECT_EQ(s.call(http::verb::get, "/api/state").result(), http::status::ok);
  EXPECT_EQ(s.call(http::verb::get, "/?token=" + s.server.token(), "", {{"Authorization", ""}}).result(),
            http::status::ok);
  // No token, a wrong one, a token of another length: 401, and nothing served.
  for (const std::string& auth : {std::string(), std::string("Bearer x"), "Bearer " + std::string(32, '0')}) {
    const auto r = s.call(http::verb::get, "/api/state", "", {{"Authorization", auth}});
    EXPECT_EQ(r.result(), http::status::unauthorized);
    EXPECT_EQ(r.body().find("\"t\""), std::string::npos);
  }
  EXPECT_EQ(s.call(http::verb::get, "/", "", {{"Authorization", ""}}).result(), http::status::unauthorized);
  // DNS rebinding: another Host; another site's page: another Origin. Both 403, token or not.
  EXPECT_EQ(
      s.call(http::verb::get, "/api/state", "", {{"Host", "evil.example:" + std::to_string(s.server.port())}}).result(),
      http::status::forbidden);
  EXPECT_EQ(
      s.call(http::verb::post, "/api/control", R"({"action":"play"})", {{"Origin", "http://evil.example"}}).result(),
      http::status::forbidden);
  EXPECT_FALSE(s.server.session()->state()["running"].get<bool>());
  EXPECT_EQ(s.call(http::verb::post, "/api/control", R"({"action":"pause"})",
                   {{"Origin", "http://127.0.0.1:" + std::to_string(s.server.port())}})
                .result(),
            http::status::ok);
}

TEST(StudioServer, BadCallsGetAMessageAndTheSimulationGoesOn) {
  Served s;
  EXPECT_EQ(s.call(http::verb::post, "/api/control", R"({"action":"play"})").result(), http::status::ok);
  const std::vector<std::tuple<http::verb, std::string, std::string, http::status>> bad = {
      {http::verb::post, "/api/set", "{not json", http::status::bad_request},
      {http::verb::post, "/api/set", R"({"rd.parameters.F": -1e300})", http::status::bad_request},
      {http::verb::post, "/api/set", R"({"grid.resolution": [8, 8]})", http::status::bad_request},
      {http::verb::post, "/api/set", R"({"sources.x.density": 1.0})", http::status::bad_request},
      {http::verb::post, "/api/set", R"({"sources.99999999999999999999.density": 1.0})", http::status::bad_request},
      {http::verb::post, "/api/set", R"([1, 2, 3])", http::status::bad_request},
      {http::verb::post, "/api/paint", R"({"kind": "meteor"})", http::status::bad_request},
      {http::verb::post, "/api/control", R"({"action": 7})", http::status::bad_request},
      {http::verb::post, "/api/view", R"({"steps_per_frame": 0})", http::status::bad_request},
      {http::verb::get, "/api/field?name=nothing", "", http::status::bad_request},
      {http::verb::get, "/api/launch", "", http::status::not_found},
      {http::verb::get, "/api/set", "", http::status::method_not_allowed},
      {http::verb::post, "/api/set", std::string(2 << 20, 'x'), http::status::payload_too_large}};
  for (const auto& [verb, target, body, status] : bad) {
    const auto r = s.call(verb, target, body);
    EXPECT_EQ(r.result(), status) << target << " " << body.substr(0, 40);
    if (r.result() != http::status::payload_too_large) {
      EXPECT_NE(r.body().find("\"error\""), std::string::npos) << r.body();
    }
  }
  const long steps = s.server.session()->state()["steps"].get<long>();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_GT(s.server.session()->state()["steps"].get<long>(), steps);
  EXPECT_TRUE(s.server.session()->state()["running"].get<bool>());
  // The good calls: the field as .npy, bitwise the session's; a set shows in the state.
  const auto f = s.call(http::verb::get, "/api/field?name=v");
  EXPECT_EQ(f.result(), http::status::ok);
  EXPECT_NE(f.body().find("'shape': (64, 64)"), std::string::npos);
  EXPECT_EQ(s.call(http::verb::post, "/api/set", R"({"rd.parameters.k": 0.061})").result(), http::status::ok);
  EXPECT_DOUBLE_EQ(
      nlohmann::json::parse(s.call(http::verb::get, "/api/state").body())["keys"]["rd.parameters.k"]["value"]
          .get<double>(),
      0.061);
}

// A client that reads one frame in 200 ms while the simulation steps
// many times: it gets the newest each time (steps skipped), nothing queues.
TEST(StudioServer, ASlowClientGetsTheNewestFrameAndFramesAreDropped) {
  Served s;
  s.call(http::verb::post, "/api/control", R"({"action":"play"})");
  boost::asio::io_context ioc;
  websocket::stream<tcp::socket> ws(ioc);
  ws.next_layer().connect({boost::asio::ip::make_address("127.0.0.1"), s.server.port()});
  ws.handshake(s.ok["Host"], "/ws?token=" + s.server.token());
  std::vector<long> steps;
  for (int k = 0; k < 5; ++k) {
    beast::flat_buffer b;
    ws.read(b);
    const std::string bytes = beast::buffers_to_string(b.data());
    ASSERT_EQ(bytes.substr(0, 4), "MFF1");
    uint32_t n = 0;
    std::memcpy(&n, bytes.data() + 4, 4);
    const nlohmann::json header = nlohmann::json::parse(bytes.substr(8, n));
    steps.push_back(header["step"].get<long>());
    EXPECT_EQ(bytes.size(), 8 + n + 768 + 64 * 64);  // one byte a cell of the 64 x 64 species
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    ws.write(boost::asio::buffer(std::string("next")));
  }
  for (size_t k = 1; k < steps.size(); ++k) EXPECT_GT(steps[k], steps[k - 1] + 1) << "frames were not dropped";
  // Frames are made only for a client that waits for one: no more than were sent, and a few.
  EXPECT_LE(s.server.session()->framesPublished(), s.server.framesSent() + 2);
  EXPECT_LE(s.server.framesSent(), 6);  // the five taken, and the one sent after the last answer
  ws.close(websocket::close_code::normal);
}

// 50 clients connect, each takes a frame and stops reading: the server holds
// them in bounded memory, sends them nothing more and makes no frame for them
// while the run goes on (the simulation spends nothing on them); they leave
// and it holds none.
TEST(StudioServer, FiftyClientsWatchAndLeave) {
  Served s;
  s.call(http::verb::post, "/api/control", R"({"action":"play"})");
  auto residentMiB = [] {  // this process's resident memory
    std::ifstream statm("/proc/self/statm");
    long pages = 0, resident = 0;
    statm >> pages >> resident;
    return double(resident) * double(sysconf(_SC_PAGESIZE)) / (1 << 20);
  };
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  const double before = residentMiB();
  boost::asio::io_context ioc;
  std::vector<std::unique_ptr<websocket::stream<tcp::socket>>> clients;
  for (int k = 0; k < 50; ++k) {
    clients.push_back(std::make_unique<websocket::stream<tcp::socket>>(ioc));
    clients.back()->next_layer().connect({boost::asio::ip::make_address("127.0.0.1"), s.server.port()});
    clients.back()->handshake(s.ok["Host"], "/ws?token=" + s.server.token());
  }
  for (auto& c : clients) {  // each takes a frame, then stops reading
    beast::flat_buffer b;
    c->read(b);
  }
  EXPECT_EQ(s.server.clients(), 50u);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));  // (the last frames in flight)
  const long steps = s.server.session()->state()["steps"].get<long>();
  const long published = s.server.session()->framesPublished(), sent = s.server.framesSent();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  EXPECT_GT(s.server.session()->state()["steps"].get<long>(), steps + 10);
  EXPECT_EQ(s.server.session()->framesPublished(), published);
  EXPECT_EQ(s.server.framesSent(), sent);
  EXPECT_LT(residentMiB() - before, 32.0) << "50 clients made the process grow by that many MiB";
  for (auto& c : clients) c->next_layer().close();
  clients.clear();
  for (int k = 0; k < 200 && s.server.clients() > 0; ++k) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_EQ(s.server.clients(), 0u);
  EXPECT_EQ(s.call(http::verb::get, "/api/state").result(), http::status::ok);
}

// A moving obstacle is shown where its motion has it now, and a hand's move
// of it is refused: its motion gives its centre.
TEST(Studio, AMovingObstacleIsShownWhereItIsAndIsNotMovedByHand) {
  const std::string scene = R"(
name = "towed"
[grid]
resolution = [32, 16]
[domain]
size = [2.0, 1.0]
[time]
dt = 0.01
steps = 1000
[[obstacles]]
radius = 0.1
motion = ["0.3 + t", "0.5"]
)";
  StudioSession s(scene, kPath, StudioOptions{});
  stepTo(s, 20);
  const nlohmann::json j = s.state();
  const double t = j["t"].get<double>();
  EXPECT_NEAR(j["elements"][0]["center"][0].get<double>(), 0.3 + t, 1e-12);
  EXPECT_NEAR(t, 0.2, 1e-9);
  EXPECT_THROW(s.paint({{"kind", "move"}, {"target", "obstacles.0"}, {"center", {0.5, 0.5}}}), UserError);
}
