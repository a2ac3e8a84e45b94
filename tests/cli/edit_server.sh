#!/bin/sh
# volmorph edit's server refuses what it must (issue 39): a request without the token or with a
# wrong one (403), a foreign Host (403), a path outside the page's files (404, never a file from
# disk), a 10 MB body (413), malformed JSON (400); it answers the API with the token, listens on
# 127.0.0.1 only, writes nothing (the scene byte for byte as it was), and stops on SIGINT with
# status 0 (LIMIT scales the hang bound, 30 s; the stop's latency is tests/bench/stop_latency.sh's). The printed URL sets a per-session cookie and redirects to the page
# without the token; every answer, refusals too, carries nosniff and a Content-Security-Policy, and
# every error is JSON.
# usage: edit_server.sh VOLMORPH SOURCE_DIR [LIMIT]
set -eu
. "$(dirname "$0")/lib.sh"
limit=${3:-1}
command -v curl >/dev/null || { echo "curl is missing (tools/install-deps.sh installs it)"; exit 1; }
default_scene "$out/scene.toml"
cp "$out/scene.toml" "$out/before.toml"
start_editor "$out/scene.toml" --resolution 32 -q
case "$url" in http://127.0.0.1:*/?token=????????????????????????????????) ;; *) echo "URL: $url"; exit 1 ;; esac

# expect STATUS CURL_ARGS...: the request is answered STATUS.
expect() {
    want=$1
    shift
    got=$(curl -s -o "$out/body" -w '%{http_code}' "$@")
    [ "$got" = "$want" ] || { echo "expected $want, got $got: curl $*"; cat "$out/body"; echo; exit 1; }
}
H="X-Volmorph-Token: $token"
expect 403 "$base/api/state"
expect 403 "$base/"
expect 403 -H "X-Volmorph-Token: 0123456789abcdef0123456789abcdef" "$base/api/state"
expect 403 "$base/api/state?token=${token%?}"
expect 403 -H "$H" -H "Host: attacker.example:80" "$base/api/state"
expect 200 -H "$H" "$base/api/state"
grep -q '"pairs"' "$out/body" || { echo "no pairs in the state"; exit 1; }
# The printed URL: the token into a cookie named for this session, then a redirect without it.
expect 303 -D "$out/headers" "$base/?token=$token"
grep -qi '^location: /\s*$' "$out/headers" || { echo "no redirect to /:"; cat "$out/headers"; exit 1; }
cookie=$(grep -i '^set-cookie:' "$out/headers" | sed 's/^[^:]*: *//; s/;.*//' | tr -d '\r')
case "$cookie" in volmorph_edit_[0-9]*_????????=$token) ;; *) echo "cookie: $cookie"; exit 1 ;; esac
grep -i '^set-cookie:' "$out/headers" | grep -qi 'HttpOnly; SameSite=Strict; Path=/' ||
    { echo "cookie attributes:"; cat "$out/headers"; exit 1; }
expect 200 -D "$out/headers" -H "Cookie: $cookie" "$base/"
nonce=$(sed -n 's/.*<script type="importmap" nonce="\([0-9a-f]*\)".*/\1/p' "$out/body")
[ -n "$nonce" ] || { echo "the page's import map has no nonce"; exit 1; }
grep -qi "^content-security-policy: default-src 'none'; script-src 'self' 'nonce-$nonce';" "$out/headers" ||
    { echo "CSP of the page:"; cat "$out/headers"; exit 1; }
expect 200 -H "Cookie: $cookie" "$base/api/state"
# The cookie with its last hex digit changed (to 1 if it was 0, else to 0: never the same token).
case "$cookie" in *0) wrong="${cookie%?}1" ;; *) wrong="${cookie%?}0" ;; esac
expect 403 -H "Cookie: $wrong" "$base/api/state"
# Every answer, refusals included: nosniff, one CSP, and JSON errors.
for request in "$base/api/state" "-H Cookie:$cookie $base/nothing" "-H Cookie:$cookie $base/api/nothing"; do
    # shellcheck disable=SC2086
    curl -s -D "$out/headers" -o "$out/body" $request
    grep -qi '^x-content-type-options: nosniff' "$out/headers" || { echo "no nosniff: $request"; cat "$out/headers"; exit 1; }
    [ "$(grep -ci '^content-security-policy:' "$out/headers")" = 1 ] || { echo "CSP: $request"; cat "$out/headers"; exit 1; }
    grep -q '^{"error":' "$out/body" || { echo "not a JSON error: $request"; cat "$out/body"; exit 1; }
done
expect 200 -H "$H" "$base/assets/three.module.js"
# Paths outside the page's files.
expect 404 -H "$H" "$base/assets/..%2F..%2F..%2Fetc%2Fpasswd"
expect 404 -H "$H" --path-as-is "$base/assets/../../../../etc/passwd"
expect 404 -H "$H" --path-as-is "$base/../../../../etc/passwd"
expect 404 -H "$H" "$base/scene.toml"
expect 404 -H "$H" "$base/assets/"
expect 400 -H "$H" "$base/api/mesh?of=..%2Fscene.toml"
# Bodies: 10 MB refused before it is read; malformed JSON; a wrong value.
head -c 10485760 /dev/zero | tr '\0' ' ' >"$out/big.json"
expect 413 -H "$H" -H "Content-Type: application/json" --data-binary "@$out/big.json" "$base/api/set"
expect 400 -H "$H" -H "Content-Type: application/json" --data '{"key": "pair[2].target.origin", "value": [1, ' "$base/api/set"
expect 400 -H "$H" -H "Content-Type: application/json" --data '{"key": "../../etc/passwd", "value": 1}' "$base/api/set"
expect 200 -H "$H" "$base/api/state"
# 127.0.0.1 only: the port is not open on another address of this machine.
port=${base##*:}
other=$(hostname -I 2>/dev/null | awk '{print $1}')
if [ -n "$other" ]; then
    code=$(curl -s -o /dev/null -w '%{http_code}' --max-time 2 -H "$H" "http://$other:$port/api/state" || true)
    [ "$code" = "000" ] || { echo "answered on $other:$port ($code)"; exit 1; }
fi
# A second editor on the same port: refused with a message naming the port.
port_flag=$(printf '%s' "$base" | sed 's/.*://')
if "$volmorph" edit "$out/scene.toml" --port "$port_flag" --resolution 16 -q >/dev/null 2>"$out/second.err"; then
    echo "a second editor listened on the same port"; exit 1
fi
grep -q "cannot listen on 127.0.0.1:$port_flag" "$out/second.err" || { cat "$out/second.err"; exit 1; }
stop_editor "$limit"
cmp -s "$out/scene.toml" "$out/before.toml" || { echo "the scene changed"; exit 1; }
echo "edit server: every refusal as expected; stopped on SIGINT"
