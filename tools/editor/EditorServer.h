// The editor's local HTTP server (cpp-httplib): EditorSession's API and the page's files, for one
// user on this machine only.
// - It listens on 127.0.0.1 alone.
// - Every request carries the session's random token: in the cookie, or in the header
//   X-Volmorph-Token (scripts, tests). The URL printed at start holds it once: opening it sets the
//   cookie (HttpOnly, SameSite=Strict, Path=/, named per session, since a cookie for 127.0.0.1 goes
//   to every port of it) and redirects to the page without it, so that the token stays out of the
//   address bar and the browser's history. Without the token: 403. A Host other than
//   127.0.0.1:PORT or localhost:PORT (a DNS rebinding page): 403.
// - Every answer carries X-Content-Type-Options: nosniff and a Content-Security-Policy: scripts,
//   styles and requests from this origin only (the page's import map by a nonce made per answer),
//   no frames; errors are JSON {"error": message} (EditorSession.h lists the statuses).
// - It serves the files of the page's folder, listed once at start, by name; a request never
//   names a path on disk. It writes nothing but the scene (EditorSession's save).
// - Request bodies over kMaxBodyBytes are refused (413) before they are read.
#pragma once

#include <filesystem>
#include <string>

namespace volmorph {
class Interrupter;
}

namespace volmorph::editor {

class EditorSession;

/// The largest request body read: an edit is a few hundred bytes.
constexpr size_t kMaxBodyBytes = 1 << 20;

struct ServerOptions {
    int port = 0;                 ///< 0: any free port
    std::filesystem::path assets; ///< the page's folder (index.html, editor.js, three.js, ...)
    std::string token;            ///< empty: a new random one
};

/// A random token: 128 bits from the system's entropy, as 32 hex digits.
std::string randomToken();

/// Serves `session` until `interrupter` asks to stop (SIGINT or SIGTERM), which it notices within
/// 0.1 s at any moment, also before the server has started listening. Prints
/// "http://127.0.0.1:PORT/?token=..." as the first line on stdout once it listens. Throws UserError
/// when the port cannot be bound or the page's folder lacks index.html; Interrupted when asked to
/// stop before it listens.
void serve(EditorSession& session, const ServerOptions& options, Interrupter& interrupter);

} // namespace volmorph::editor
