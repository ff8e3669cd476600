// serveHttp: the module libconus_http, loaded on the first call from
// <the conus program's folder>/CONUS_HTTP_MODULE (cli/CMakeLists.txt).
#include "conus/core/error.h"
#include "conus/core/plugin.h"
#include "http_server.h"

namespace conus::cli {

void serveHttp(const std::string& host, int port, const HttpHandler& handler, const std::function<void(int)>& listening) {
    using ServeFunction = int (*)(const std::string&, int, const HttpHandler&, const std::function<void(int)>&);
    static const ServeFunction serve = reinterpret_cast<ServeFunction (*)()>(
        loadPluginSymbol(reinterpret_cast<const void*>(&serveHttp), CONUS_HTTP_MODULE, "conusServeHttpFunction"))();
    if (serve(host, port, handler, listening) < 0)
        throw Error(ErrorCode::Io, "cannot listen on " + host + ":" + std::to_string(port) + " (in use, or not an address here)");
}

}  // namespace conus::cli
