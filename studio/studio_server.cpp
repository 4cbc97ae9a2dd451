#include "studio/studio_server.h"

#include <array>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <random>
#include <set>
#include <string_view>
#include <thread>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/http.hpp>
#include <boost/beast/websocket.hpp>
#include <fmt/format.h>

#include "scenes/scene_loader.h"

namespace morphoflow {

extern const std::string_view kStudioPage;

namespace asio = boost::asio;
namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;
using tcp = asio::ip::tcp;
using asio::awaitable;
using asio::use_awaitable;
using Request = http::request<http::string_body>;
using Response = http::response<http::string_body>;

namespace {

std::string randomToken() {
  std::random_device rd;
  std::string t;
  for (int k = 0; k < 4; ++k) t += fmt::format("{:08x}", rd());
  return t;
}

// Equal in a time that does not depend on where they differ.
bool sameSecret(std::string_view a, std::string_view b) {
  if (a.size() != b.size()) return false;
  unsigned char d = 0;
  for (size_t i = 0; i < a.size(); ++i) d |= static_cast<unsigned char>(a[i] ^ b[i]);
  return d == 0;
}

std::string percentDecoded(std::string_view s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '+') out += ' ';
    else if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(uint8_t(s[i + 1])) && std::isxdigit(uint8_t(s[i + 2]))) {
      out += char(std::stoi(std::string(s.substr(i + 1, 2)), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

// The value for `name` in a list of name=value pairs ("" when absent).
std::string listValue(std::string_view list, char separator, std::string_view name) {
  while (!list.empty()) {
    const size_t end = list.find(separator);
    std::string_view pair = list.substr(0, end);
    while (!pair.empty() && pair.front() == ' ') pair.remove_prefix(1);
    const size_t eq = pair.find('=');
    if (pair.substr(0, eq) == name)
      return eq == std::string_view::npos ? std::string() : std::string(pair.substr(eq + 1));
    if (end == std::string_view::npos) break;
    list = list.substr(end + 1);
  }
  return {};
}

// A target's path, its query's value for `name`, a Cookie header's value for `name`.
std::string_view pathOf(std::string_view target) { return target.substr(0, target.find('?')); }
std::string queryValue(std::string_view target, std::string_view name) {
  const size_t q = target.find('?');
  return q == std::string_view::npos ? std::string() : percentDecoded(listValue(target.substr(q + 1), '&', name));
}
std::string cookieValue(std::string_view header, std::string_view name) { return listValue(header, ';', name); }

std::string_view sv(beast::string_view s) { return {s.data(), s.size()}; }

bool isLoopback(const std::string& address) {
  const asio::ip::address a = asio::ip::make_address(address);
  return a.is_loopback();
}

}  // namespace

struct StudioServer::Impl {
  ServerOptions options;
  StudioOptions studio;
  std::string sceneDir;
  asio::io_context ioc{1};
  tcp::acceptor acceptor{ioc};
  std::thread thread;
  unsigned short port = 0;
  mutable std::mutex mutex;
  std::shared_ptr<StudioSession> session;
  struct Watcher;
  std::set<Watcher*> watchers;  // the WebSocket clients (I/O thread only)
  std::atomic<long> sent{0};
  std::atomic<size_t> clients{0}, connections{0};
  std::atomic<bool> wakePending{false};
  std::atomic<long> wanting{0};  // clients that took their last frame (each wants the next)

  // Every frame wakes the writers of the clients that took their last frame
  // (at most one wake-up queued; a client still busy with a frame costs nothing).
  void listen(const std::shared_ptr<StudioSession>& s) {
    s->onFrame([this] {
      if (wakePending.exchange(true)) return;
      asio::post(ioc, [this] {
        wakePending = false;
        for (Watcher* w : watchers)
          if (w->ready) w->wake.cancel();
      });
    }, [this] { return wanting > 0; });
  }

  std::shared_ptr<StudioSession> current() const {
    std::lock_guard<std::mutex> lk(mutex);
    return session;
  }

  // The Host header: loopback names on this port, or any host when the
  // server listens on a network (the token still guards it).
  bool hostAllowed(std::string_view host) const {
    const std::string p = ":" + std::to_string(port);
    for (const std::string& h : {"127.0.0.1" + p, "localhost" + p, "[::1]" + p, options.listen + p})
      if (host == h) return true;
    return !isLoopback(options.listen);
  }

  // Refused requests: a foreign Host or Origin (403), no token (401).
  std::optional<Response> refusal(const Request& req) const {
    auto refuse = [&](http::status status, const std::string& why) {
      Response r{status, req.version()};
      r.set(http::field::content_type, "text/plain; charset=utf-8");
      r.body() = why + "\n";
      r.keep_alive(false);
      r.prepare_payload();
      return r;
    };
    const std::string host(sv(req[http::field::host]));
    if (!hostAllowed(host))
      return refuse(http::status::forbidden, "forbidden: the Host '" + host + "' is not this studio's");
    const std::string_view origin = sv(req[http::field::origin]);
    if (!origin.empty() && origin != "http://" + host)
      return refuse(http::status::forbidden,
                    "forbidden: requests from another site (Origin " + std::string(origin) + ") are refused");
    std::string token = queryValue(sv(req.target()), "token");
    const std::string_view auth = sv(req[http::field::authorization]);
    if (token.empty() && auth.substr(0, 7) == "Bearer ") token = std::string(auth.substr(7));
    if (token.empty()) token = cookieValue(sv(req[http::field::cookie]), cookieName());
    if (!sameSecret(token, options.token))
      return refuse(http::status::unauthorized,
                    "unauthorized: open the address with ?token= that `morphoflow studio` printed, or send "
                    "Authorization: Bearer TOKEN");
    return std::nullopt;
  }

  // The page's cookie: set when the page is opened with the token, so that a
  // reload (the address no longer shows the token) is let in. Strict
  // same-site: another site's page never sends it.
  std::string cookieName() const { return "morphoflow-studio-" + std::to_string(port); }

  static Response reply(const Request& req, http::status status, std::string body, const std::string& type) {
    Response r{status, req.version()};
    r.set(http::field::content_type, type);
    r.set(http::field::cache_control, "no-store");
    r.set("X-Content-Type-Options", "nosniff");
    r.keep_alive(req.keep_alive());
    r.body() = std::move(body);
    r.prepare_payload();
    return r;
  }
  static Response json(const Request& req, const nlohmann::json& j, http::status status = http::status::ok) {
    return reply(req, status, j.dump() + "\n", "application/json");
  }
  static Response error(const Request& req, http::status status, const std::string& message) {
    return json(req, {{"error", message}}, status);
  }

  std::vector<std::string> shippedScenes() const {
    std::vector<std::string> names;
    std::error_code ec;
    for (auto it = std::filesystem::recursive_directory_iterator(sceneDir, ec); !ec && it != decltype(it)();
         it.increment(ec))
      if (it->is_regular_file() && it->path().extension() == ".toml")
        names.push_back(std::filesystem::relative(it->path(), sceneDir).string());
    std::sort(names.begin(), names.end());
    return names;
  }

  Response open(const Request& req, const nlohmann::json& body) {
    const std::string name = body.is_object() ? body.value("scene", "") : "";
    const std::vector<std::string> names = shippedScenes();
    if (std::find(names.begin(), names.end(), name) == names.end())
      return error(req, http::status::bad_request, "no shipped scene '" + name + "' (GET /api/scenes lists them)");
    const std::string path = (std::filesystem::path(sceneDir) / name).string();
    const std::string text = readSceneText(path);
    if (const std::shared_ptr<StudioSession> old = current()) old->close();  // (one GPU simulation at a time)
    auto s = std::make_shared<StudioSession>(text, path, studio);
    listen(s);
    {
      std::lock_guard<std::mutex> lk(mutex);
      session = s;
    }
    return json(req, {{"ok", true}, {"scene", name}});
  }

  // The API (docs/studio.md); a UserError is a 400 with its message.
  Response handle(const Request& req) {
    const std::string path(pathOf(sv(req.target())));
    const bool get = req.method() == http::verb::get, post = req.method() == http::verb::post;
    if (path == "/" || path == "/index.html") {
      if (!get) return error(req, http::status::method_not_allowed, "the page is GET /");
      Response page = reply(req, http::status::ok, std::string(kStudioPage), "text/html; charset=utf-8");
      page.set(http::field::set_cookie, cookieName() + "=" + options.token + "; Path=/; HttpOnly; SameSite=Strict");
      return page;
    }
    if (path.rfind("/api/", 0) != 0) return error(req, http::status::not_found, "no such page: " + path);
    nlohmann::json body;
    if (post) {
      body = nlohmann::json::parse(req.body(), nullptr, false);
      if (body.is_discarded()) return error(req, http::status::bad_request, "the body is not JSON");
    }
    const std::string call = path.substr(5);
    try {
      const std::shared_ptr<StudioSession> s = current();
      if (call == "scenes" && get)
        return json(req, {{"scenes", shippedScenes()}, {"open", s ? s->state()["scene"] : nlohmann::json()}});
      if (call == "open" && post) return open(req, body);
      if (!s)
        return error(req, http::status::conflict,
                     "no scene is open: POST /api/open {\"scene\": NAME} (GET /api/scenes)");
      if (call == "state" && get) return json(req, s->state());
      if (call == "scene" && get)
        return reply(req, http::status::ok, s->sceneText(), "application/toml; charset=utf-8");
      if (call == "field" && get) {
        Response r =
            reply(req, http::status::ok, s->fieldNpy(queryValue(sv(req.target()), "name")), "application/octet-stream");
        r.set(http::field::content_disposition,
              "attachment; filename=\"" + queryValue(sv(req.target()), "name") + ".npy\"");
        return r;
      }
      if (call == "control" && post) return json(req, s->control(body));
      if (call == "set" && post) return json(req, s->set(body));
      if (call == "paint" && post) return json(req, s->paint(body));
      if (call == "view" && post) return json(req, s->view(body));
      if (call == "render" && post) return json(req, s->render());
    } catch (const UserError& e) {
      return error(req, http::status::bad_request, e.what());
    } catch (const std::exception& e) {
      return error(req, http::status::bad_request, e.what());
    }
    const std::set<std::string> known = {"scenes",  "open", "state", "scene", "field",
                                         "control", "set",  "paint", "view",  "render"};
    if (known.count(call)) return error(req, http::status::method_not_allowed, "wrong method for /api/" + call);
    return error(req, http::status::not_found, "no such call: /api/" + call);
  }

  // One watching client: the writer sends the newest frame once the client
  // has taken the one before (it answers each frame with a message), so a
  // slow client skips frames and nothing queues for it, here or in the kernel.
  struct Watcher {
    explicit Watcher(websocket::stream<beast::tcp_stream> s, asio::io_context& ioc)
        : ws(std::move(s)), wake(ioc) {}
    websocket::stream<beast::tcp_stream> ws;
    asio::steady_timer wake;
    bool ready = true, done = false;
  };

  awaitable<void> frames(Watcher& w) {
    watchers.insert(&w);
    ++wanting;  // (a new client wants a frame: w.ready)
    std::shared_ptr<const std::string> last;
    beast::error_code ec;
    while (!w.done) {
      const std::shared_ptr<StudioSession> s = current();
      std::shared_ptr<const std::string> f = s ? s->frame() : nullptr;
      if (w.ready && f && f != last) {
        w.ready = false;
        --wanting;
        w.ws.binary(true);
        co_await w.ws.async_write(asio::buffer(*f), asio::redirect_error(use_awaitable, ec));
        if (ec) break;
        last = f;
        ++sent;
        continue;
      }
      w.wake.expires_after(std::chrono::seconds(1));
      co_await w.wake.async_wait(asio::redirect_error(use_awaitable, ec));
    }
    w.done = true;  // (the reader counts no more answers)
    watchers.erase(&w);
    if (w.ready) --wanting;
    w.ready = false;
  }

  awaitable<void> websocketClient(beast::tcp_stream stream, Request req) {
    Watcher w(websocket::stream<beast::tcp_stream>(std::move(stream)), ioc);
    beast::get_lowest_layer(w.ws).expires_never();
    w.ws.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
    w.ws.read_message_max(4096);
    w.ws.auto_fragment(false);  // a frame goes as one WebSocket frame in one write, not in 4 KiB pieces
    beast::error_code ec;
    co_await w.ws.async_accept(req, asio::redirect_error(use_awaitable, ec));
    if (ec) co_return;
    ++clients;
    // The reader: each message says the client took a frame; a close or an error ends both.
    bool readerDone = false;
    asio::co_spawn(ioc, [this, &w, &readerDone]() -> awaitable<void> {
      beast::flat_buffer in;
      beast::error_code rec;
      for (;;) {
        in.consume(in.size());
        co_await w.ws.async_read(in, asio::redirect_error(use_awaitable, rec));
        if (rec) break;
        if (!w.ready && !w.done) ++wanting;
        w.ready = true;
        w.wake.cancel();
      }
      w.done = true;
      w.wake.cancel();
      readerDone = true;
    }, asio::detached);
    co_await frames(w);
    beast::get_lowest_layer(w.ws).socket().close(ec);
    --clients;
    asio::steady_timer wait(ioc);  // (the reader ends on the closed socket before w goes)
    while (!readerDone) {
      wait.expires_after(std::chrono::milliseconds(5));
      co_await wait.async_wait(asio::redirect_error(use_awaitable, ec));
    }
  }

  // After refusing a request whose body is still arriving: stop sending, then
  // read and drop what the client is still writing (for 2 s at most), so the
  // close does not reset the connection before the client reads the answer.
  static awaitable<void> lingeringClose(beast::tcp_stream& stream) {
    beast::error_code ec;
    stream.socket().shutdown(tcp::socket::shutdown_send, ec);
    stream.expires_after(std::chrono::seconds(2));
    std::array<char, 64 * 1024> sink;
    while (!ec) co_await stream.async_read_some(asio::buffer(sink), asio::redirect_error(use_awaitable, ec));
  }

  awaitable<void> connection(tcp::socket socket) {
    struct Count {
      std::atomic<size_t>& n;
      ~Count() { --n; }
    } count{connections};
    beast::tcp_stream stream(std::move(socket));
    beast::flat_buffer buffer;
    beast::error_code ec;
    for (;;) {
      http::request_parser<http::string_body> parser;
      parser.header_limit(16 * 1024);
      parser.body_limit(options.maxBody);
      stream.expires_after(std::chrono::seconds(30));
      co_await http::async_read(stream, buffer, parser, asio::redirect_error(use_awaitable, ec));
      if (ec == http::error::body_limit || ec == http::error::header_limit) {
        Response r{ec == http::error::body_limit ? http::status::payload_too_large
                                                 : http::status::request_header_fields_too_large,
                   11};
        r.body() = fmt::format("{{\"error\": \"the request is larger than the studio takes ({} bytes of body)\"}}\n",
                               options.maxBody);
        r.keep_alive(false);
        r.prepare_payload();
        co_await http::async_write(stream, r, asio::redirect_error(use_awaitable, ec));
        co_await lingeringClose(stream);
        co_return;
      }
      if (ec) co_return;
      Request req = parser.release();
      if (std::optional<Response> no = refusal(req)) {
        co_await http::async_write(stream, *no, asio::redirect_error(use_awaitable, ec));
        co_return;
      }
      if (websocket::is_upgrade(req)) {
        if (pathOf(sv(req.target())) != "/ws" || clients >= options.maxClients) {
          Response r = error(req, http::status::service_unavailable,
                             fmt::format("the studio serves {} watching clients at most", options.maxClients));
          r.keep_alive(false);
          co_await http::async_write(stream, r, asio::redirect_error(use_awaitable, ec));
          co_return;
        }
        co_await websocketClient(std::move(stream), std::move(req));
        co_return;
      }
      Response res = handle(req);
      const bool keep = res.keep_alive();
      co_await http::async_write(stream, res, asio::redirect_error(use_awaitable, ec));
      if (ec || !keep) co_return;
    }
  }

  awaitable<void> accept() {
    for (;;) {
      beast::error_code ec;
      tcp::socket socket = co_await acceptor.async_accept(asio::redirect_error(use_awaitable, ec));
      if (ec == asio::error::operation_aborted) co_return;
      if (ec) continue;
      if (connections >= options.maxConnections) {
        socket.close(ec);
        continue;
      }
      ++connections;
      socket.set_option(tcp::no_delay(true), ec);  // (a frame's last segment is not held back for an acknowledgement)
      asio::co_spawn(ioc, connection(std::move(socket)), asio::detached);
    }
  }
};

StudioServer::StudioServer(const ServerOptions& server, const StudioOptions& studio, const std::string& sceneText,
                           const std::string& scenePath, const std::string& sceneDir)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.options = server;
  if (m.options.token.empty()) m.options.token = randomToken();
  m.studio = studio;
  m.sceneDir = sceneDir;
  if (!scenePath.empty()) {
    m.session = std::make_shared<StudioSession>(sceneText, scenePath, studio);
    m.listen(m.session);
  }
  beast::error_code ec;
  const asio::ip::address address = asio::ip::make_address(server.listen, ec);
  if (ec)
    throw UserError({"--listen", 0, 0}, "", "'" + server.listen + "' is not an IP address",
                    "e.g. 127.0.0.1 or 0.0.0.0");
  const tcp::endpoint at(address, server.port);
  m.acceptor.open(at.protocol());
  m.acceptor.set_option(asio::socket_base::reuse_address(true));
  m.acceptor.bind(at, ec);
  if (ec)
    throw UserError({"--port", 0, 0}, "",
                    fmt::format("cannot listen on {}:{}: {}", server.listen, server.port, ec.message()),
                    "give another --port, or 0 for any free one");
  m.acceptor.listen();
  m.port = m.acceptor.local_endpoint().port();
  asio::co_spawn(m.ioc, m.accept(), asio::detached);
  m.thread = std::thread([&m] { m.ioc.run(); });
}

StudioServer::~StudioServer() { stop(); }

void StudioServer::stop() {
  if (!impl_->thread.joinable()) return;
  impl_->ioc.stop();
  impl_->thread.join();
  std::lock_guard<std::mutex> lk(impl_->mutex);
  if (impl_->session) impl_->session->onFrame({});
}

unsigned short StudioServer::port() const { return impl_->port; }
const std::string& StudioServer::token() const { return impl_->options.token; }
std::string StudioServer::url() const {
  const std::string host = isLoopback(impl_->options.listen) ? "127.0.0.1" : impl_->options.listen;
  return fmt::format("http://{}:{}/?token={}", host, impl_->port, impl_->options.token);
}
std::shared_ptr<StudioSession> StudioServer::session() const { return impl_->current(); }
long StudioServer::framesSent() const { return impl_->sent; }
size_t StudioServer::clients() const { return impl_->clients; }

}  // namespace morphoflow
