//! What stands in front of the server (the threat model is in `docs/serve.md`, "Security").
//!
//! On every route ([`site`]): the `Host` header must name this server (its bound address, or a
//! loopback alias when it listens on loopback) — a foreign name is DNS rebinding — and an
//! `Origin`, when sent, must be this server's own — anything else is another web page.
//! On `/api/*` ([`check`]): requests from another site (`Sec-Fetch-Site`) are refused; a command
//! (any method but GET and HEAD) must be `Content-Type: application/json` and carry the session
//! token; beyond loopback every request must carry the token; then a rate limit (a token bucket
//! shared by all clients).

use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use axum::extract::{Request, State};
use axum::http::{HeaderMap, HeaderValue, Method, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use super::api::ApiError;

/// The header the page sends the session token in.
pub const TOKEN_HEADER: &str = "x-plantwide-token";

/// Why a request was refused before it reached a route.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Refusal {
    /// The `Host` header names another server (DNS rebinding) or is missing.
    #[error(
        "host `{got}` is not this server's address: open {expected} (another name for this machine is admitted \
         with --allow-host NAME)"
    )]
    Host {
        /// The header's value (`(none)` when missing).
        got: String,
        /// This server's address.
        expected: String,
    },
    /// The request comes from another web page (its `Origin`).
    #[error("requests from origin `{got}` are refused: this server answers only its own page at {expected}")]
    Origin {
        /// The header's value.
        got: String,
        /// This server's address.
        expected: String,
    },
    /// The browser says the request comes from another site.
    #[error("requests from another site (Sec-Fetch-Site: {0}) are refused: use this server's own page")]
    Site(String),
    /// A command is not JSON.
    #[error(
        "a command must be sent with Content-Type: application/json (charset utf-8 at most), not `{0}`; \
         e.g. curl -H 'Content-Type: application/json'"
    )]
    ContentType(String),
    /// A command without the session token.
    #[error(
        "a command needs this session's token in the X-Plantwide-Token header: the page at {0} sends it, \
         and the server printed it at start (`token: …`)"
    )]
    NoSessionToken(String),
    /// A request without the printed token on a server listening beyond loopback.
    #[error(
        "this server listens beyond 127.0.0.1: give the token it printed at start (Authorization: Bearer TOKEN, \
         X-Plantwide-Token: TOKEN, or ?token=TOKEN)"
    )]
    NoToken,
    /// Over the rate limit.
    #[error("more than {0} requests per second: slow down, or start the server with a higher --rate")]
    Rate(f64),
}

impl Refusal {
    fn status(&self) -> StatusCode {
        match self {
            Refusal::Host { .. } | Refusal::Origin { .. } | Refusal::Site(_) | Refusal::NoSessionToken(_) => {
                StatusCode::FORBIDDEN
            }
            Refusal::ContentType(_) => StatusCode::UNSUPPORTED_MEDIA_TYPE,
            Refusal::NoToken => StatusCode::UNAUTHORIZED,
            Refusal::Rate(_) => StatusCode::TOO_MANY_REQUESTS,
        }
    }
}

impl IntoResponse for Refusal {
    fn into_response(self) -> Response {
        ApiError(self.status(), self.to_string()).into_response()
    }
}

/// The host names this server answers to, with its port.
#[derive(Debug, Clone)]
pub struct Hosts {
    port: u16,
    /// Host names (lower case, IPv6 in brackets) accepted with `port`.
    names: Vec<String>,
    /// Listening on every address (0.0.0.0 or ::): any IP literal is one of ours.
    any_ip: bool,
    /// Where to send a refused client.
    address: String,
}

impl Hosts {
    /// The hosts of a server bound to `addr`, and `extra` names (`--allow-host`).
    pub fn new(addr: SocketAddr, extra: &[String]) -> Hosts {
        let ip = addr.ip();
        let literal = |ip: IpAddr| if ip.is_ipv6() { format!("[{ip}]") } else { ip.to_string() };
        let mut names = vec![literal(ip)];
        if ip.is_loopback() {
            names.extend([
                "localhost".to_string(),
                literal(Ipv4Addr::LOCALHOST.into()),
                literal(Ipv6Addr::LOCALHOST.into()),
            ]);
        }
        names.extend(extra.iter().map(|n| n.to_ascii_lowercase()));
        Hosts {
            port: addr.port(),
            any_ip: ip.is_unspecified(),
            address: format!("http://{}:{}/", literal(ip), addr.port()),
            names,
        }
    }

    /// This server's address, as printed.
    pub fn address(&self) -> &str {
        &self.address
    }

    /// Whether `host` (`name[:port]`, as in a `Host` header) is this server.
    pub fn accepts(&self, host: &str) -> bool {
        let Some((name, port)) = split_host(host) else { return false };
        if port.unwrap_or(80) != self.port {
            return false;
        }
        let name = name.to_ascii_lowercase();
        self.names.contains(&name) || (self.any_ip && is_ip_literal(&name))
    }

    /// Whether `origin` (`http://name[:port]`) is this server's own page.
    fn accepts_origin(&self, origin: &str) -> bool {
        origin.strip_prefix("http://").is_some_and(|rest| !rest.contains('/') && self.accepts(rest))
    }
}

/// `name[:port]` → (name, port); IPv6 names keep their brackets. `None` when malformed.
fn split_host(host: &str) -> Option<(&str, Option<u16>)> {
    let (name, port) = if host.starts_with('[') {
        let end = host.find(']')?;
        let (name, rest) = host.split_at(end + 1);
        (name, if rest.is_empty() { None } else { Some(rest.strip_prefix(':')?) })
    } else {
        match host.split_once(':') {
            Some((name, port)) => (name, Some(port)),
            None => (host, None),
        }
    };
    let port = match port {
        Some(p) => Some(p.parse().ok()?),
        None => None,
    };
    (!name.is_empty()).then_some((name, port))
}

fn is_ip_literal(name: &str) -> bool {
    name.parse::<Ipv4Addr>().is_ok()
        || name.strip_prefix('[').and_then(|n| n.strip_suffix(']')).is_some_and(|n| n.parse::<Ipv6Addr>().is_ok())
}

/// The guard's state.
#[derive(Clone)]
pub struct Guard {
    /// The session token.
    pub token: Arc<String>,
    /// Every `/api/` request needs the token (the server listens beyond loopback), not only commands.
    pub everywhere: bool,
    hosts: Arc<Hosts>,
    /// Requests per second sustained; twice as many are taken in a burst.
    rate: f64,
    bucket: Arc<Mutex<(f64, Instant)>>,
}

impl Guard {
    /// A guard for a server at `hosts` with the session `token` (asked of every `/api/` request
    /// when `everywhere`, else of commands only), admitting `rate` requests per second.
    pub fn new(token: String, everywhere: bool, hosts: Hosts, rate: f64) -> Guard {
        let bucket = Arc::new(Mutex::new((2.0 * rate, Instant::now())));
        Guard { token: Arc::new(token), everywhere, hosts: Arc::new(hosts), rate, bucket }
    }

    /// Take one request from the bucket; false when it is empty.
    fn admit(&self) -> bool {
        let Ok(mut b) = self.bucket.lock() else { return false };
        let now = Instant::now();
        b.0 = (b.0 + self.rate * now.duration_since(b.1).as_secs_f64()).min(2.0 * self.rate);
        b.1 = now;
        if b.0 >= 1.0 {
            b.0 -= 1.0;
            true
        } else {
            false
        }
    }

    /// Whether `req` carries the token (`X-Plantwide-Token`, `Authorization: Bearer …` or `?token=…`).
    fn carries_token(&self, req: &Request) -> bool {
        let h = req.headers();
        let given = text(h, TOKEN_HEADER).or_else(|| text(h, header::AUTHORIZATION)?.strip_prefix("Bearer "));
        let query = req.uri().query().and_then(|q| q.split('&').find_map(|kv| kv.strip_prefix("token=")));
        given.or(query).is_some_and(|t| same(t.as_bytes(), self.token.as_bytes()))
    }

    /// Host and origin of any request.
    fn site(&self, req: &Request) -> Result<(), Refusal> {
        let expected = || self.hosts.address().to_string();
        let host = text(req.headers(), header::HOST);
        if !host.is_some_and(|h| self.hosts.accepts(h)) {
            return Err(Refusal::Host { got: clip(host.unwrap_or("(none)")), expected: expected() });
        }
        match text(req.headers(), header::ORIGIN) {
            Some(o) if !self.hosts.accepts_origin(o) => Err(Refusal::Origin { got: clip(o), expected: expected() }),
            _ => Ok(()),
        }
    }

    /// Site, content type, token and rate of an `/api/` request.
    fn api(&self, req: &Request) -> Result<(), Refusal> {
        if let Some(s) = text(req.headers(), "sec-fetch-site")
            && !matches!(s, "same-origin" | "none")
        {
            return Err(Refusal::Site(clip(s)));
        }
        let command = !matches!(*req.method(), Method::GET | Method::HEAD);
        if command {
            json_content(req.headers())?;
        }
        if !self.carries_token(req) {
            if self.everywhere {
                return Err(Refusal::NoToken);
            }
            if command {
                return Err(Refusal::NoSessionToken(self.hosts.address().to_string()));
            }
        }
        if !self.admit() {
            return Err(Refusal::Rate(self.rate));
        }
        Ok(())
    }
}

fn text(headers: &HeaderMap, name: impl axum::http::header::AsHeaderName) -> Option<&str> {
    headers.get(name).and_then(|v| v.to_str().ok())
}

/// A header's value as a message quotes it: at most 100 characters.
fn clip(value: &str) -> String {
    value.chars().take(100).collect()
}

/// `Ok` for `application/json` with at most a `charset=utf-8` parameter; else the refusal
/// quoting what was sent.
fn json_content(headers: &HeaderMap) -> Result<(), Refusal> {
    let Some(value) = headers.get(header::CONTENT_TYPE) else { return Err(Refusal::ContentType("(none)".into())) };
    let got = || Refusal::ContentType(clip(&String::from_utf8_lossy(value.as_bytes())));
    let text = value.to_str().map_err(|_| got())?;
    let mut parts = text.split(';').map(str::trim);
    let essence = parts.next().is_some_and(|m| m.eq_ignore_ascii_case("application/json"));
    let charset = |p: &str| {
        p.split_once('=').is_some_and(|(k, v)| {
            k.trim().eq_ignore_ascii_case("charset") && v.trim().trim_matches('"').eq_ignore_ascii_case("utf-8")
        })
    };
    let params: Vec<&str> = parts.filter(|p| !p.is_empty()).collect();
    if essence && params.len() <= 1 && params.iter().all(|p| charset(p)) { Ok(()) } else { Err(got()) }
}

/// Equality that takes as long whatever the first difference (no timing oracle for the token).
fn same(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

/// Middleware on every route: 403 for a foreign `Host` or `Origin`; every answer forbids framing
/// (another page showing ours in a frame to steer clicks).
pub async fn site(State(g): State<Guard>, req: Request, next: Next) -> Response {
    let mut response = match g.site(&req) {
        Ok(()) => next.run(req).await,
        Err(r) => r.into_response(),
    };
    let h = response.headers_mut();
    h.insert(header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY"));
    h.insert(header::CONTENT_SECURITY_POLICY, HeaderValue::from_static("frame-ancestors 'none'"));
    response
}

/// Middleware on `/api/*`: 403 from another site or a command without the session token, 415 for
/// a command not in JSON, 401 without the printed token beyond loopback, 429 over the rate.
pub async fn check(State(g): State<Guard>, req: Request, next: Next) -> Response {
    match g.api(&req) {
        Ok(()) => next.run(req).await,
        Err(r) => r.into_response(),
    }
}

/// A fresh token: 128 bits from the operating system's generator, in hex.
///
/// # Errors
/// When `/dev/urandom` cannot be read.
pub fn new_token() -> std::io::Result<String> {
    use std::io::Read;
    let mut bytes = [0u8; 16];
    std::fs::File::open("/dev/urandom")?.read_exact(&mut bytes)?;
    Ok(bytes.iter().map(|b| format!("{b:02x}")).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hosts(addr: &str) -> Hosts {
        Hosts::new(addr.parse().expect("an address"), &[])
    }

    #[test]
    fn a_loopback_server_answers_to_its_aliases_on_its_port_only() {
        let h = hosts("127.0.0.1:8080");
        for ok in ["127.0.0.1:8080", "localhost:8080", "LOCALHOST:8080", "[::1]:8080"] {
            assert!(h.accepts(ok), "{ok}");
        }
        for bad in ["evil.example:8080", "127.0.0.1:8081", "127.0.0.1", "localhost", "", ":8080", "[::1", "a:b:c"] {
            assert!(!h.accepts(bad), "{bad}");
        }
        assert!(hosts("127.0.0.1:80").accepts("localhost"));
        assert!(h.accepts_origin("http://localhost:8080"));
        for bad in ["null", "https://127.0.0.1:8080", "http://evil.example:8080", "http://127.0.0.1:8080/x"] {
            assert!(!h.accepts_origin(bad), "{bad}");
        }
    }

    #[test]
    fn a_server_beyond_loopback_answers_to_its_address_and_the_names_allowed() {
        let h = Hosts::new("10.0.0.5:9000".parse().expect("an address"), &["Plant.Example".into()]);
        assert!(h.accepts("10.0.0.5:9000") && h.accepts("plant.example:9000"));
        assert!(!h.accepts("localhost:9000") && !h.accepts("10.0.0.6:9000"));
        let any = hosts("0.0.0.0:9000");
        assert!(any.accepts("192.168.1.7:9000") && any.accepts("[fe80::1]:9000"));
        assert!(!any.accepts("rebind.example:9000"));
    }

    #[test]
    fn a_command_is_json_with_at_most_a_utf8_charset() {
        let with = |v: &str| {
            let mut h = HeaderMap::new();
            h.insert(header::CONTENT_TYPE, HeaderValue::from_str(v).expect("a header"));
            json_content(&h)
        };
        for ok in [
            "application/json",
            "Application/JSON",
            "application/json; charset=utf-8",
            "application/json;charset=\"UTF-8\"",
        ] {
            assert_eq!(with(ok), Ok(()), "{ok}");
        }
        for bad in [
            "text/plain",
            "application/x-www-form-urlencoded",
            "multipart/form-data; boundary=x",
            "application/json; charset=latin1",
            "application/json; charset=utf-8; x=y",
            "application/jsonx",
        ] {
            assert_eq!(with(bad), Err(Refusal::ContentType(bad.to_string())), "{bad}");
        }
        assert_eq!(json_content(&HeaderMap::new()), Err(Refusal::ContentType("(none)".into())));
    }
}
