#include "EditorServer.h"

#include "EditorSession.h"

#include <volmorph/core/Diagnostics.h>
#include <volmorph/core/FileText.h>
#include <volmorph/core/Interrupter.h>

#include <httplib.h>
#include <nlohmann/json.hpp>
#include <sys/socket.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

namespace volmorph::editor {
namespace {

struct Asset {
    std::string type, bytes;
};

std::string contentType(const std::filesystem::path& file)
{
    const std::string ext = file.extension().string();
    if (ext == ".html") return "text/html; charset=utf-8";
    if (ext == ".js" || ext == ".mjs") return "text/javascript; charset=utf-8";
    if (ext == ".css") return "text/css; charset=utf-8";
    if (ext == ".png") return "image/png";
    if (ext == ".svg") return "image/svg+xml";
    return "application/octet-stream";
}

/// The page's files by name, read once: what the server can send is fixed before it listens.
std::map<std::string, Asset> readAssets(const std::filesystem::path& folder)
{
    std::map<std::string, Asset> assets;
    std::error_code ec;
    for (const auto& entry : std::filesystem::directory_iterator(folder, ec)) {
        if (std::optional<std::string> bytes = readFileText(entry.path()))
            assets[entry.path().filename().string()] = {contentType(entry.path()),
                                                        std::move(*bytes)};
    }
    if (!assets.count("index.html"))
        throw UserError(SourceLocation{folder.string()},
                        "the editor's page is not there (no index.html): build the target "
                        "volmorph_editor_page, or install volmorph");
    return assets;
}

/// Equal strings, in a time that does not depend on where they differ.
bool sameSecret(const std::string& a, const std::string& b)
{
    if (a.size() != b.size()) return false;
    unsigned char diff = 0;
    for (size_t i = 0; i < a.size(); ++i) diff |= static_cast<unsigned char>(a[i] ^ b[i]);
    return diff == 0;
}

/// The value of cookie `name` in a Cookie header ("a=1; b=2").
std::string cookie(const std::string& header, const std::string& name)
{
    std::istringstream in(header);
    std::string item;
    while (std::getline(in, item, ';')) {
        const size_t start = item.find_first_not_of(' ');
        if (start == std::string::npos) continue;
        item = item.substr(start);
        if (item.compare(0, name.size() + 1, name + "=") == 0) return item.substr(name.size() + 1);
    }
    return "";
}

struct Gate {
    std::string token, cookieName;
    int port = 0;

    bool hostAllowed(const httplib::Request& request) const
    {
        const std::string host = request.get_header_value("Host");
        const std::string suffix = ":" + std::to_string(port);
        return host == "127.0.0.1" + suffix || host == "localhost" + suffix;
    }

    bool tokenGiven(const httplib::Request& request) const
    {
        return sameSecret(request.get_param_value("token"), token) ||
               sameSecret(request.get_header_value("X-Volmorph-Token"), token) ||
               sameSecret(cookie(request.get_header_value("Cookie"), cookieName), token);
    }
};

void refuse(httplib::Response& response, int status, const std::string& message)
{
    response.status = status;
    response.set_content(nlohmann::json{{"error", message}}.dump(), "application/json");
}

/// This origin's scripts, styles and requests only; `nonce` admits the page's inline import map.
std::string contentSecurityPolicy(const std::string& nonce = "")
{
    return "default-src 'none'; script-src 'self'" +
           (nonce.empty() ? "" : " 'nonce-" + nonce + "'") +
           "; style-src 'self'; img-src 'self' data:; connect-src 'self'; base-uri 'none'; "
           "form-action 'none'; frame-ancestors 'none'";
}

void setHeader(httplib::Response& response, const std::string& name, const std::string& value)
{
    response.headers.erase(name);
    response.set_header(name, value);
}

/// The page with a fresh nonce on its inline import map (the one inline script it has).
std::string withNonce(std::string page, const std::string& nonce)
{
    const std::string tag = "<script type=\"importmap\"";
    const size_t at = page.find(tag);
    if (at != std::string::npos) page.insert(at + tag.size(), " nonce=\"" + nonce + "\"");
    return page;
}

void route(httplib::Server& server, EditorSession& session, const Gate& gate,
           const std::map<std::string, Asset>& assets)
{
    server.Get("/", [&](const httplib::Request& request, httplib::Response& response) {
        response.set_header("Cache-Control", "no-store");
        if (request.has_param("token")) { // the printed URL: the token into the cookie, then away
            response.set_header("Set-Cookie", gate.cookieName + "=" + gate.token +
                                                  "; HttpOnly; SameSite=Strict; Path=/");
            response.set_redirect("/", 303);
            return;
        }
        const std::string nonce = randomToken();
        setHeader(response, "Content-Security-Policy", contentSecurityPolicy(nonce));
        const Asset& page = assets.at("index.html");
        response.set_content(withNonce(page.bytes, nonce), page.type);
    });
    server.Get("/assets/([A-Za-z0-9_.-]+)",
               [&](const httplib::Request& request, httplib::Response& response) {
                   const auto found = assets.find(request.matches[1].str());
                   if (found == assets.end()) return refuse(response, 404, "no such file");
                   response.set_content(found->second.bytes, found->second.type);
               });
    const auto api = [&](const httplib::Request& request, httplib::Response& response) {
        std::map<std::string, std::string> query;
        for (const auto& [key, value] : request.params) query.emplace(key, value);
        const Reply reply = session.handle(request.method, request.path, query, request.body);
        response.status = reply.status;
        response.set_header("Cache-Control", "no-store");
        response.set_content(reply.body, reply.type);
    };
    server.Get("/api/.*", api);
    server.Post("/api/.*", api);
}

} // namespace

std::string randomToken()
{
    std::random_device entropy;
    std::string token;
    char digits[9];
    for (int i = 0; i < 4; ++i) {
        std::snprintf(digits, sizeof digits, "%08x", unsigned(entropy()));
        token += digits;
    }
    return token;
}

void serve(EditorSession& session, const ServerOptions& options, Interrupter& interrupter)
{
    const std::map<std::string, Asset> assets = readAssets(options.assets);
    httplib::Server server;
    server.set_payload_max_length(kMaxBodyBytes);
    // SO_REUSEADDR alone: cpp-httplib also sets SO_REUSEPORT, with which a second editor would
    // bind the same port and the two would share its requests.
    server.set_socket_options([](int socket) {
        const int yes = 1;
        ::setsockopt(socket, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    });
    const int port = options.port
                         ? (server.bind_to_port("127.0.0.1", options.port) ? options.port : -1)
                         : server.bind_to_any_port("127.0.0.1");
    if (port < 0)
        throw UserError(SourceLocation{"--port"},
                        "cannot listen on 127.0.0.1:" + std::to_string(options.port) +
                            " (in use?): choose another port");
    const Gate gate{options.token.empty() ? randomToken() : options.token,
                    "volmorph_edit_" + std::to_string(port) + "_" + randomToken().substr(0, 8),
                    port};
    server.set_pre_routing_handler(
        [&gate](const httplib::Request& request, httplib::Response& response) {
            setHeader(response, "X-Content-Type-Options", "nosniff");
            setHeader(response, "Content-Security-Policy", contentSecurityPolicy());
            if (!gate.hostAllowed(request)) {
                refuse(response, 403, "unexpected Host");
                return httplib::Server::HandlerResponse::Handled;
            }
            if (!gate.tokenGiven(request)) {
                refuse(response, 403, "this page needs the URL volmorph edit printed (its token)");
                return httplib::Server::HandlerResponse::Handled;
            }
            return httplib::Server::HandlerResponse::Unhandled;
        });
    // What cpp-httplib refuses itself (no route, a body over the limit): JSON and the same headers.
    server.set_error_handler([](const httplib::Request&, httplib::Response& response) {
        setHeader(response, "X-Content-Type-Options", "nosniff");
        if (!response.has_header("Content-Security-Policy"))
            setHeader(response, "Content-Security-Policy", contentSecurityPolicy());
        if (response.body.empty())
            refuse(response, response.status,
                   response.status == 404   ? "no such page"
                   : response.status == 413 ? "request body too large"
                                            : "refused");
    });
    route(server, session, gate, assets);
    throwIfInterrupted(&interrupter);
    std::printf("http://127.0.0.1:%d/?token=%s\n", port, gate.token.c_str());
    std::fflush(stdout);
    std::atomic<bool> ended{false};
    std::thread listener([&server, &ended] {
        server.listen_after_bind();
        ended = true;
    });
    while (!interrupter.stopRequested() && !ended)
        std::this_thread::sleep_for(std::chrono::milliseconds(100));
    // cpp-httplib's stop() does nothing until listen_after_bind() has set the server running: a
    // stop request that came first would leave the listener in accept() for good. So wait for it
    // to run (or end), then stop it.
    while (!ended) {
        if (server.is_running()) {
            server.stop();
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    listener.join();
}

} // namespace volmorph::editor
