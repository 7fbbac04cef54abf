//! What stands in front of the API: the access token (required unless the server listens on
//! 127.0.0.1 or ::1 only) and a rate limit (a token bucket shared by all clients).

use std::sync::{Arc, Mutex};
use std::time::Instant;

use axum::extract::{Request, State};
use axum::http::StatusCode;
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};

use super::api::ApiError;

/// The guard's state.
#[derive(Clone)]
pub struct Guard {
    /// The token asked for, if any.
    pub token: Option<Arc<String>>,
    /// Requests per second sustained; twice as many are taken in a burst.
    rate: f64,
    bucket: Arc<Mutex<(f64, Instant)>>,
}

impl Guard {
    /// A guard asking for `token` (none: open), admitting `rate` requests per second.
    pub fn new(token: Option<String>, rate: f64) -> Guard {
        Guard { token: token.map(Arc::new), rate, bucket: Arc::new(Mutex::new((2.0 * rate, Instant::now()))) }
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

    /// Whether `req` carries the token (`Authorization: Bearer …` or `?token=…`).
    fn authorized(&self, req: &Request) -> bool {
        let Some(token) = &self.token else { return true };
        let bearer = req
            .headers()
            .get(axum::http::header::AUTHORIZATION)
            .and_then(|v| v.to_str().ok())
            .and_then(|v| v.strip_prefix("Bearer "));
        let query = req
            .uri()
            .query()
            .and_then(|q| q.split('&').find_map(|kv| kv.strip_prefix("token=")))
            .map(|t| t.to_string());
        bearer.map(str::to_string).or(query).is_some_and(|t| same(t.as_bytes(), token.as_bytes()))
    }
}

/// Equality that takes as long whatever the first difference (no timing oracle for the token).
fn same(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

/// Middleware: 401 without the token, 429 over the rate.
pub async fn check(State(g): State<Guard>, req: Request, next: Next) -> Response {
    if !g.authorized(&req) {
        let msg = "this server listens beyond 127.0.0.1: give the token it printed at start (Authorization: Bearer TOKEN, or ?token=TOKEN)";
        return ApiError(StatusCode::UNAUTHORIZED, msg.into()).into_response();
    }
    if !g.admit() {
        let msg = format!("more than {} requests per second", g.rate);
        return ApiError(StatusCode::TOO_MANY_REQUESTS, msg).into_response();
    }
    next.run(req).await
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
