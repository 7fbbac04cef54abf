//! The HTTP routes: the page and its assets, and the JSON API the page itself uses.
//!
//! `GET /api/state` (`?at=sync`: the exact values at the sync point), `POST /api/command`,
//! `GET /api/plant` (what the page draws), `GET /api/journal` (the scenario reproducing the run),
//! `GET /api/snapshots`, `GET /api/stream?paths=a,b` (server-sent trend samples).
//! A refused command is HTTP 400 with the library's message; the run goes on.

use std::collections::HashMap;
use std::convert::Infallible;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Arc, RwLock};

use axum::Json;
use axum::body::Bytes;
use axum::extract::{Query, State};
use axum::http::{StatusCode, header};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use futures_util::Stream;
use plantwide::solve::dynamic::LiveError;
use serde::Deserialize;
use serde_json::{Value, json};
use tokio::sync::{broadcast, oneshot};

use super::command::parse_command;
use super::sim::{Published, Request};

/// Most trend streams open at once.
pub const MAX_STREAMS: usize = 32;

/// What every handler shares.
#[derive(Clone)]
pub struct App {
    /// Requests to the simulation thread.
    pub tx: Sender<Request>,
    /// The latest publication.
    pub latest: Arc<RwLock<Arc<Published>>>,
    /// Publications, for trend streams.
    pub stream: broadcast::Sender<Arc<Published>>,
    /// Every value's path, in the order of `Published::values`.
    pub paths: Arc<Vec<String>>,
    /// Index of each path.
    pub index: Arc<HashMap<String, usize>>,
    /// Trend paths when a stream names none.
    pub default_trend: Arc<Vec<String>>,
    /// The plant as the page draws it (`GET /api/plant`).
    pub plant: Arc<Value>,
    /// Trend streams open.
    pub streams: Arc<AtomicUsize>,
}

/// An error response: a status and a message, as `{"error": message}`.
#[derive(Debug)]
pub struct ApiError(pub StatusCode, pub String);

impl IntoResponse for ApiError {
    fn into_response(self) -> Response {
        (self.0, Json(json!({ "error": self.1 }))).into_response()
    }
}

impl From<LiveError> for ApiError {
    fn from(e: LiveError) -> Self {
        let status = match e {
            LiveError::Refused(_) => StatusCode::BAD_REQUEST,
            // A stopped run refuses to step: the request is fine, the run's state is not.
            LiveError::Stopped(_) | LiveError::Failed(_) => StatusCode::CONFLICT,
            LiveError::Sim(_) => StatusCode::BAD_REQUEST,
        };
        ApiError(status, e.to_string())
    }
}

/// Ask the simulation thread and wait for its answer.
async fn ask<T>(app: &App, make: impl FnOnce(oneshot::Sender<T>) -> Request) -> Result<T, ApiError> {
    let (tx, rx) = oneshot::channel();
    let gone = || ApiError(StatusCode::SERVICE_UNAVAILABLE, "the simulation has stopped".into());
    app.tx.send(make(tx)).map_err(|_| gone())?;
    rx.await.map_err(|_| gone())
}

/// `{"time", "running", "values": {path: SI}}` and the clock's details.
fn state_json(app: &App, p: &Published) -> Value {
    let values: serde_json::Map<String, Value> =
        app.paths.iter().zip(&p.values).map(|(k, v)| (k.clone(), json!(v))).collect();
    json!({
        "time": p.time,
        "running": p.running,
        "speed": p.speed,
        "sync_time": p.sync_time,
        "behind": p.behind,
        "pending": p.pending,
        "failure": p.failure,
        "values": values,
    })
}

/// Query of `GET /api/state`.
#[derive(Debug, Deserialize)]
pub struct StateQuery {
    /// `sync`: the values at the sync point rather than at the time shown.
    at: Option<String>,
}

/// `GET /api/state`.
pub async fn state(State(app): State<App>, Query(q): Query<StateQuery>) -> Result<Json<Value>, ApiError> {
    let p = match q.at.as_deref() {
        None | Some("shown") => app.latest.read().map(|p| p.clone()).map_err(|_| poisoned())?,
        Some("sync") => Arc::new(ask(&app, Request::AtSync).await?),
        Some(other) => return Err(ApiError(StatusCode::BAD_REQUEST, format!("at={other}: give `sync` or `shown`"))),
    };
    Ok(Json(state_json(&app, &p)))
}

fn poisoned() -> ApiError {
    ApiError(StatusCode::INTERNAL_SERVER_ERROR, "the state is unavailable".into())
}

/// `POST /api/command`: one command object; `{"ok": true, "at": sync point}` or 400.
pub async fn command(State(app): State<App>, body: Bytes) -> Result<Json<Value>, ApiError> {
    let cmd = parse_command(&body).map_err(|e| ApiError(StatusCode::BAD_REQUEST, e.to_string()))?;
    let at = ask(&app, |tx| Request::Command(cmd, tx)).await??;
    Ok(Json(json!({ "ok": true, "at": at })))
}

/// `GET /api/plant`.
pub async fn plant(State(app): State<App>) -> Json<Value> {
    Json((*app.plant).clone())
}

/// `GET /api/journal`: the scenario file that reproduces the run so far.
pub async fn journal(State(app): State<App>) -> Result<Json<Value>, ApiError> {
    let spec = ask(&app, Request::Journal).await?;
    serde_json::to_value(spec).map(Json).map_err(|e| ApiError(StatusCode::INTERNAL_SERVER_ERROR, e.to_string()))
}

/// `GET /api/snapshots`.
pub async fn snapshots(State(app): State<App>) -> Result<Json<Value>, ApiError> {
    Ok(Json(json!(ask(&app, Request::Snapshots).await?)))
}

/// Query of `GET /api/stream`.
#[derive(Debug, Deserialize)]
pub struct StreamQuery {
    /// Comma-separated paths (default: every controller's measurement, setpoint and output).
    paths: Option<String>,
}

/// Counts an open stream; uncounts it when the stream ends.
struct StreamSlot(Arc<AtomicUsize>);

impl Drop for StreamSlot {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// `GET /api/stream`: a server-sent event per publication, `{"t", "running", "v": [values of the
/// paths asked, in order]}`; the first event names the paths.
pub async fn stream(
    State(app): State<App>,
    Query(q): Query<StreamQuery>,
) -> Result<Sse<impl Stream<Item = Result<Event, Infallible>>>, ApiError> {
    let names: Vec<String> = match &q.paths {
        Some(p) => p.split(',').map(|s| s.trim().to_string()).filter(|s| !s.is_empty()).collect(),
        None => app.default_trend.to_vec(),
    };
    let mut idx = Vec::with_capacity(names.len());
    for n in &names {
        let i = app.index.get(n).ok_or_else(|| ApiError(StatusCode::BAD_REQUEST, format!("no path `{n}`")))?;
        idx.push(*i);
    }
    if app.streams.fetch_add(1, Ordering::SeqCst) >= MAX_STREAMS {
        app.streams.fetch_sub(1, Ordering::SeqCst);
        return Err(ApiError(StatusCode::SERVICE_UNAVAILABLE, format!("{MAX_STREAMS} trend streams are open")));
    }
    let slot = StreamSlot(app.streams.clone());
    let head = Event::default().event("paths").data(json!(names).to_string());
    let rx = app.stream.subscribe();
    let samples = futures_util::stream::unfold((rx, idx, slot), |(mut rx, idx, slot)| async move {
        loop {
            match rx.recv().await {
                Ok(p) => {
                    let v: Vec<f64> = idx.iter().map(|&i| p.values[i]).collect();
                    let data = json!({ "t": p.time, "running": p.running, "v": v }).to_string();
                    return Some((Ok(Event::default().data(data)), (rx, idx, slot)));
                }
                Err(broadcast::error::RecvError::Lagged(_)) => continue,
                Err(broadcast::error::RecvError::Closed) => return None,
            }
        }
    });
    let first = futures_util::stream::iter([Ok(head)]);
    Ok(Sse::new(futures_util::StreamExt::chain(first, samples)).keep_alive(KeepAlive::default()))
}

/// The page with the session `token` in its `plantwide-token` meta tag (empty: the page takes
/// the token from its address, `?token=`).
pub fn page_html(token: &str) -> String {
    include_str!("assets/index.html").replace("{{token}}", token)
}

/// The page (never cached: it carries the session's token).
pub async fn page(html: Arc<String>) -> impl IntoResponse {
    let headers = [(header::CONTENT_TYPE, "text/html; charset=utf-8"), (header::CACHE_CONTROL, "no-store")];
    (headers, (*html).clone())
}

/// The page's script.
pub async fn script() -> impl IntoResponse {
    ([(header::CONTENT_TYPE, "text/javascript; charset=utf-8")], include_str!("assets/app.js"))
}

/// The page's style sheet.
pub async fn style() -> impl IntoResponse {
    ([(header::CONTENT_TYPE, "text/css; charset=utf-8")], include_str!("assets/app.css"))
}
