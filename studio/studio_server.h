// The studio's web server (Boost.Beast over one I/O thread): the page, the
// JSON API the page and scripts use (docs/studio.md), and a WebSocket that
// sends each client the newest frame, dropping the frames a slow client
// has not taken. It binds loopback unless told otherwise, refuses every
// request without its token, with a foreign Host or Origin, or past its
// limits, and never lets a request stop the simulation.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "studio/studio_session.h"

namespace morphoflow {

struct ServerOptions {
  std::string listen = "127.0.0.1";  // the address to bind ("0.0.0.0": every interface)
  unsigned short port = 0;           // 0: any free port
  std::string token;                 // empty: a random one
  size_t maxClients = 64;            // WebSocket clients at once
  size_t maxConnections = 256;       // connections at once
  size_t maxBody = 1 << 20;          // bytes of a request's body
};

class StudioServer {
 public:
  // A scene (its text and path), or none (empty path): the page then offers
  // the .toml files under sceneDir.
  StudioServer(const ServerOptions& server, const StudioOptions& studio, const std::string& sceneText,
               const std::string& scenePath, const std::string& sceneDir);
  ~StudioServer();
  StudioServer(const StudioServer&) = delete;
  StudioServer& operator=(const StudioServer&) = delete;

  unsigned short port() const;
  const std::string& token() const;
  // The page's address with the token: http://HOST:PORT/?token=...
  std::string url() const;
  // The session (null until a scene is open).
  std::shared_ptr<StudioSession> session() const;
  // Frames written to WebSocket clients, and clients connected now.
  long framesSent() const;
  size_t clients() const;
  // Stops serving (the destructor does too).
  void stop();

  struct Impl;

 private:
  std::unique_ptr<Impl> impl_;
};

}  // namespace morphoflow
