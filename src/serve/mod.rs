//! `plantwide serve`: the browser simulator. HTTP only: the page (embedded in the binary), the
//! JSON API it uses, trend streams, the checks in front of them ([`guard`]: host, origin, content
//! type, session token), request size and rate limits. The
//! simulation itself is [`plantwide::solve::dynamic::Live`], run on a thread of its own
//! ([`sim`]); the page's view of the plant comes from the plant's accessors ([`plant_view`]).

mod api;
mod command;
mod guard;
mod plant_view;
mod sim;

use std::collections::HashMap;
use std::net::{IpAddr, Ipv4Addr, Ipv6Addr, SocketAddr};
use std::sync::atomic::AtomicUsize;
use std::sync::{Arc, RwLock, mpsc};
use std::time::Duration;

use axum::Router;
use axum::extract::DefaultBodyLimit;
use axum::routing::{get, post};
use plantwide::solve::dynamic::{Live, LiveError};
use tokio::sync::broadcast;

use api::App;
use guard::{Guard, Hosts};
use sim::{Published, Sim};

/// Largest request body accepted \[bytes\].
pub const MAX_BODY: usize = 16 * 1024;

/// Why the server could not run.
#[derive(Debug, thiserror::Error)]
pub enum ServeError {
    /// The address could not be bound, or the runtime not started.
    #[error("{0}")]
    Io(#[from] std::io::Error),
    /// The clock's start speed was refused.
    #[error(transparent)]
    Live(#[from] LiveError),
}

/// How to serve.
#[derive(Debug, Clone)]
pub struct Options {
    /// Address to listen on.
    pub bind: IpAddr,
    /// Port (0: any free one).
    pub port: u16,
    /// Clock speed at start.
    pub speed: f64,
    /// Start paused.
    pub paused: bool,
    /// Requests per second the API admits (twice as many in a burst).
    pub rate: f64,
    /// Host names answered besides the bound address (and its loopback aliases).
    pub allow_hosts: Vec<String>,
    /// Stop after this many seconds (tests).
    pub exit_after: Option<f64>,
}

/// Whether every `/api/` request needs the token: on any address but 127.0.0.1 and ::1 (on those,
/// commands only, and the page carries it).
fn token_everywhere(bind: IpAddr) -> bool {
    bind != IpAddr::V4(Ipv4Addr::LOCALHOST) && bind != IpAddr::V6(Ipv6Addr::LOCALHOST)
}

/// Serve `live` until the process ends (or `exit_after`). Prints the address and the session
/// token on stdout once listening.
///
/// # Errors
/// [`ServeError`] when the address cannot be bound.
pub fn serve(live: Live, opts: &Options) -> Result<(), ServeError> {
    let token = guard::new_token()?;
    let paths = live.paths();
    let mut index: HashMap<String, usize> = paths.iter().enumerate().map(|(k, p)| (p.clone(), k)).collect();
    // A tag's name is its value's path too (`XMEAS(7)` for `XMEAS(7).value`).
    for (name, t) in live.plant().tags() {
        if let Some(&k) = index.get(&live.plant().vars()[t.var].path) {
            index.insert(name.clone(), k);
        }
    }
    let plant = plant_view::describe(live.plant(), &paths);
    let default_trend = plant_view::default_trend(live.plant());
    let first = Published {
        time: live.sync_time(),
        sync_time: live.sync_time(),
        running: !opts.paused,
        speed: opts.speed,
        behind: false,
        pending: 0,
        failure: None,
        values: live.values_at(live.sync_time()),
    };
    let latest = Arc::new(RwLock::new(Arc::new(first)));
    let (stream, _) = broadcast::channel(64);
    let mut sim = Sim::new(live, opts.speed, latest.clone(), stream.clone())?;
    if opts.paused {
        sim.pause();
    }
    let (tx, rx) = mpsc::channel();
    let worker = std::thread::spawn(move || sim.run(&rx));
    let app = App {
        tx,
        latest,
        stream,
        paths: Arc::new(paths),
        index: Arc::new(index),
        default_trend: Arc::new(default_trend),
        plant: Arc::new(plant),
        streams: Arc::new(AtomicUsize::new(0)),
    };
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
    rt.block_on(listen(app, token, opts))?;
    // The router (and with it every sender) is gone: the simulation thread ends.
    worker.join().map_err(|_| std::io::Error::other("the simulation thread panicked"))?;
    Ok(())
}

/// Bind, print where, and serve the router.
async fn listen(app: App, token: String, opts: &Options) -> Result<(), ServeError> {
    let listener = tokio::net::TcpListener::bind(SocketAddr::new(opts.bind, opts.port)).await?;
    let hosts = Hosts::new(listener.local_addr()?, &opts.allow_hosts);
    let everywhere = token_everywhere(opts.bind);
    let page = Arc::new(api::page_html(if everywhere { "" } else { &token }));
    let guard = Guard::new(token, everywhere, hosts.clone(), opts.rate);
    let t = &guard.token;
    if everywhere {
        println!("plantwide serve: listening on {}?token={t}\ntoken: {t}", hosts.address());
    } else {
        println!(
            "plantwide serve: listening on {}\ntoken: {t} (commands carry it as X-Plantwide-Token; the page does)",
            hosts.address()
        );
    }
    use std::io::Write;
    let _ = std::io::stdout().flush();
    let api = Router::new()
        .route("/state", get(api::state))
        .route("/command", post(api::command))
        .route("/plant", get(api::plant))
        .route("/journal", get(api::journal))
        .route("/snapshots", get(api::snapshots))
        .route("/stream", get(api::stream))
        .with_state(app)
        .layer(axum::middleware::from_fn_with_state(guard.clone(), guard::check))
        .layer(DefaultBodyLimit::max(MAX_BODY));
    let router = Router::new()
        .route("/", get(move || api::page(page.clone())))
        .route("/app.js", get(api::script))
        .route("/app.css", get(api::style))
        .nest("/api", api)
        .layer(axum::middleware::from_fn_with_state(guard, guard::site));
    if let Some(s) = opts.exit_after {
        // Open trend streams never end, so no graceful shutdown would: the process ends.
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_secs_f64(s.max(0.0)));
            std::process::exit(0);
        });
    }
    axum::serve(listener, router).await?;
    Ok(())
}
