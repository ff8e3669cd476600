// The HTTP server under `conus serve`, in words of our own: cpp-httplib (and the OpenSSL, zlib and
// Brotli it is built with) sits in the module libconus_http (http_module.cpp, <libdir>/conus),
// loaded only when `conus serve` runs, so no other command loads them (core/plugin.h).
#pragma once

#include <functional>
#include <map>
#include <string>

namespace conus::cli {

struct HttpRequest {
    std::string path;                           // percent-decoded, as the client asked
    std::map<std::string, std::string> params;  // the query's, percent-decoded (the first of a repeated name)
};

struct HttpReply {
    int status = 200;
    std::string contentType = "text/plain; charset=utf-8";
    std::string body;
};

using HttpHandler = std::function<HttpReply(const HttpRequest&)>;

// Answers every GET with `handler` (called on the server's worker threads) on host:port (port 0:
// any free one), calling `listening` with the port once bound; returns when the server stops.
// Throws conus::Error(Io) when it cannot listen there.
void serveHttp(const std::string& host, int port, const HttpHandler& handler, const std::function<void(int)>& listening);

}  // namespace conus::cli
