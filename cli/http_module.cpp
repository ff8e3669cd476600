// The module libconus_http: serveHttp's work through cpp-httplib (see http_server.h). It reports
// failures by return value, so nothing but the standard library crosses the module's edge.
#include <httplib.h>

#include "http_server.h"

namespace {

// -1: could not listen; otherwise 0 once the server stops.
int serve(const std::string& host, int port, const conus::cli::HttpHandler& handler, const std::function<void(int)>& listening) {
    httplib::Server server;
    // Browsers hold a few idle keep-alive connections, each a worker until it times out: more
    // workers than the library's default (8), and a short keep-alive, keep bad or slow clients from
    // starving the rest.
    server.new_task_queue = [] { return new httplib::ThreadPool(32); };
    server.set_payload_max_length(1 << 16);  // requests are GETs
    server.set_read_timeout(5, 0);
    server.set_write_timeout(30, 0);
    server.set_keep_alive_max_count(20);
    server.set_keep_alive_timeout(2);
    // SO_REUSEADDR (a restart binds while old connections linger) but not the library's default
    // SO_REUSEPORT, which lets a second server, or anyone's, bind the same port and take half the requests.
    socket_t listening_socket = INVALID_SOCKET;
    server.set_socket_options([&listening_socket](socket_t sock) {
        int yes = 1;
        setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
        listening_socket = sock;
    });
    server.Get(R"(/.*)", [&handler](const httplib::Request& request, httplib::Response& response) {
        conus::cli::HttpRequest r;
        r.path = request.path;
        for (const auto& [name, value] : request.params) r.params.emplace(name, value);
        conus::cli::HttpReply reply;
        try {
            reply = handler(r);
        } catch (const std::exception& e) {
            reply = {500, "text/plain; charset=utf-8", std::string(e.what()) + "\n"};
        }
        response.status = reply.status;
        response.set_content(std::move(reply.body), reply.contentType);
        response.set_header("Cache-Control", "no-cache");
    });
    // What httplib refuses itself (a malformed request line, a path it will not route): one line too.
    server.set_error_handler([](const httplib::Request&, httplib::Response& response) {
        if (response.body.empty()) response.set_content(std::to_string(response.status) + "\n", "text/plain; charset=utf-8");
    });
    const int bound = port == 0 ? server.bind_to_any_port(host) : (server.bind_to_port(host, port) ? port : -1);
    if (bound <= 0) return -1;
    // Debian's library listens with a backlog of 5: past 5 connections not yet accepted, the kernel
    // drops new ones and their clients retry after 1, 3, 7... s (100 requests at once timed out
    // after 60 s). Listening again on the bound socket sets the backlog to the system's largest.
    if (listening_socket != INVALID_SOCKET) ::listen(listening_socket, SOMAXCONN);
    listening(bound);
    return server.listen_after_bind() ? 0 : -1;
}

}  // namespace

using ServeFunction = int (*)(const std::string&, int, const conus::cli::HttpHandler&, const std::function<void(int)>&);

extern "C" __attribute__((visibility("default"))) ServeFunction conusServeHttpFunction() { return &serve; }
