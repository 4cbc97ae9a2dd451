#include "studio/studio_bench.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>
#include <utility>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <toml++/toml.h>

#include "core/parallel.h"
#include "run/run_clock.h"
#include "scenes/scene_loader.h"
#include "sim/simulation_factory.h"
#include "studio/studio_server.h"

namespace morphoflow {

namespace {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = boost::asio::ip::tcp;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// A shipped scene with its resolutions set (fluid, chemicals) and no end.
std::string sceneText(const std::string& path, int dimension, int fluid, int chemicals) {
  toml::table t = toml::parse_file(path);
  auto cube = [&](int n) {
    toml::array a;
    for (int k = 0; k < dimension; ++k) a.push_back(n);
    return a;
  };
  t["grid"].as_table()->insert_or_assign("resolution", cube(fluid));
  t["rd"].as_table()->insert_or_assign("resolution", cube(chemicals));
  t["time"].as_table()->insert_or_assign("steps", 100000000);
  std::ostringstream out;
  out << t;
  return out.str();
}

// Steps/s of the scene's simulation alone, the clock `run` uses, for `seconds`.
double aloneRate(const Scene& scene, double seconds) {
  auto run = [&](auto sim) {
    const RunClock clock(runTime(scene));
    sim->advance(clock.dt(*sim), 2);  // (first touches)
    const long first = sim->steps();
    const Clock::time_point start = Clock::now();
    while (secondsSince(start) < seconds) sim->advance(clock.dt(*sim), 1);
    return double(sim->steps() - first) / secondsSince(start);
  };
  const auto quiet = [](const std::string&) {};
  return scene.dimension == 2 ? run(makeSimulation<2>(scene, Backend::TBB, quiet, quiet))
                              : run(makeSimulation<3>(scene, Backend::TBB, quiet, quiet));
}

// A watching client on its own thread: takes every frame (answering each)
// and notes the step and arrival time of each.
class Watcher {
 public:
  Watcher(unsigned short port, const std::string& token) : ws_(ioc_) {
    ws_.next_layer().connect({boost::asio::ip::make_address("127.0.0.1"), port});
    ws_.next_layer().set_option(tcp::no_delay(true));  // (as browsers do)
    ws_.handshake("127.0.0.1:" + std::to_string(port), "/ws?token=" + token);
    thread_ = std::thread([this] {
      beast::error_code ec;
      while (!stop_) {
        beast::flat_buffer b;
        ws_.read(b, ec);
        if (ec) break;
        const std::string bytes = beast::buffers_to_string(b.data());
        uint32_t n = 0;
        std::memcpy(&n, bytes.data() + 4, 4);
        lastStep_ = nlohmann::json::parse(bytes.substr(8, n))["step"].get<long>();
        ++frames_;
        ws_.write(boost::asio::buffer(std::string("next")), ec);
      }
    });
  }
  ~Watcher() {
    stop_ = true;
    beast::error_code ec;
    ws_.next_layer().shutdown(tcp::socket::shutdown_both, ec);
    thread_.join();
  }
  long lastStep() const { return lastStep_; }
  long frames() const { return frames_; }

 private:
  boost::asio::io_context ioc_;
  websocket::stream<tcp::socket> ws_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<long> lastStep_{-1}, frames_{0};
};

nlohmann::json post(unsigned short port, const std::string& token, const std::string& target,
                    const nlohmann::json& body) {
  boost::asio::io_context ioc;
  beast::tcp_stream stream(ioc);
  stream.connect({boost::asio::ip::make_address("127.0.0.1"), port});
  http::request<http::string_body> req{http::verb::post, target, 11};
  req.set(http::field::host, "127.0.0.1:" + std::to_string(port));
  req.set(http::field::authorization, "Bearer " + token);
  req.body() = body.dump();
  req.prepare_payload();
  http::write(stream, req);
  beast::flat_buffer b;
  http::response<http::string_body> res;
  http::read(stream, b, res);
  if (res.result() != http::status::ok) throw std::runtime_error("studio bench: " + target + " answered " + res.body());
  return nlohmann::json::parse(res.body());
}

struct Row {
  std::string name;
  double alone = 0, watched = 0, framesPerSecond = 0, frameBytes = 0, frameMs = 0, latencyMedian = 0, latencyMax = 0;
};

Row measure(const std::string& name, const std::string& text, const std::string& path, double seconds, bool latency) {
  Row row{name};
  const Scene scene = parseScene(text, path);
  StudioServer server(ServerOptions{}, StudioOptions{}, text, path, "");
  Watcher watcher(server.port(), server.token());
  // Interleaved: alone (the studio paused), then watched, three times; medians.
  std::vector<double> alone, watched, fps;
  for (int round = 0; round < 3; ++round) {
    alone.push_back(aloneRate(scene, seconds));
    post(server.port(), server.token(), "/api/control", {{"action", "play"}});
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
    const long s0 = server.session()->state()["steps"].get<long>(), f0 = watcher.frames();
    const Clock::time_point start = Clock::now();
    std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    const double dt = secondsSince(start);
    watched.push_back(double(server.session()->state()["steps"].get<long>() - s0) / dt);
    fps.push_back(double(watcher.frames() - f0) / dt);
    post(server.port(), server.token(), "/api/control", {{"action", "pause"}});
  }
  row.alone = median(alone), row.watched = median(watched), row.framesPerSecond = median(fps);
  row.frameBytes = double(server.session()->frame()->size());
  row.frameMs = server.session()->state()["frame_ms"].get<double>();
  if (latency) {  // a deposit posted while running, to the first frame computed after it
    post(server.port(), server.token(), "/api/control", {{"action", "play"}});
    std::vector<double> ms;
    for (int k = 0; k < 20; ++k) {
      const double x = 0.2 + 0.03 * k;
      const Clock::time_point t0 = Clock::now();
      const long step =
          post(server.port(), server.token(), "/api/paint",
               {{"kind", "deposit"}, {"field", "v"}, {"center", {x, 0.5}}, {"radius", 0.03}, {"value", 0.5}})["step"];
      while (watcher.lastStep() <= step) std::this_thread::sleep_for(std::chrono::microseconds(200));
      ms.push_back(1e3 * secondsSince(t0));
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    row.latencyMedian = median(ms), row.latencyMax = *std::max_element(ms.begin(), ms.end());
  }
  return row;
}

}  // namespace

void runStudioBench(const std::string& sceneDir, double seconds, const std::string& json) {
  const std::string cavity = sceneDir + "/coupled/cavity_gray_scott.toml",
                    cavity3 = sceneDir + "/coupled/cavity_gray_scott_3d.toml";
  fmt::print(
      "studio: {} thread(s); steps/s alone and in the studio with one client taking every frame (steps per frame 1),\n"
      "medians of 3 interleaved rounds of {:g} s; edit to frame: a deposit posted to the first frame after it (20 "
      "edits)\n\n",
      hardwareThreads(), seconds);
  const std::vector<Row> rows = {
      measure("2D 128^2 fluid, 256^2 chemicals", sceneText(cavity, 2, 128, 256), cavity, seconds, true),
      measure("3D 64^3 fluid, 64^3 chemicals", sceneText(cavity3, 3, 64, 64), cavity3, seconds, false)};
  fmt::print("{:<34} {:>10} {:>10} {:>7} {:>9} {:>9} {:>9} {:>18}\n", "case", "alone/s", "studio/s", "cost", "frames/s",
             "frame KiB", "frame ms", "edit to frame ms");
  nlohmann::json out = nlohmann::json::array();
  for (const Row& r : rows) {
    const double cost = r.alone / r.watched - 1.0;  // the extra time a step takes in the studio
    fmt::print(
        "{:<34} {:>10.1f} {:>10.1f} {:>6.1f}% {:>9.1f} {:>9.1f} {:>9.2f} {:>18}\n", r.name, r.alone, r.watched,
        100 * cost, r.framesPerSecond, r.frameBytes / 1024, r.frameMs,
        r.latencyMedian > 0 ? fmt::format("{:.1f} (max {:.1f})", r.latencyMedian, r.latencyMax) : std::string("-"));
    out.push_back({{"case", r.name},
                   {"steps_per_second_alone", r.alone},
                   {"steps_per_second_studio", r.watched},
                   {"cost", cost},
                   {"frames_per_second", r.framesPerSecond},
                   {"frame_bytes", r.frameBytes},
                   {"frame_ms", r.frameMs},
                   {"edit_to_frame_ms_median", r.latencyMedian},
                   {"edit_to_frame_ms_max", r.latencyMax}});
  }
  if (!json.empty())
    std::ofstream(json) << nlohmann::json{{"suite", "studio"}, {"threads", hardwareThreads()}, {"cases", out}}.dump(2)
                        << "\n";
}

}  // namespace morphoflow
