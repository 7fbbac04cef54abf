//! Guards for the failures that kill the process: the mutant about to run is written to
//! `target/fuzz-current.txt` first (an abort or a stack overflow leaves it there to replay), a
//! watchdog thread aborts a mutant that runs over the time limit, and a counting global allocator
//! aborts on any request, or live total above the warm-up baseline, over the memory limit. Both print the mutant first.

use std::alloc::{GlobalAlloc, Layout, System};
use std::io::Write;
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

/// Largest single allocation, and largest live total, a mutant may ask for.
pub const MEMORY_LIMIT: usize = 2 << 30;
/// Time a mutant may take: it fails when both its wall time and its CPU time pass this (wall time
/// alone would fail a mutant for the other builds sharing the machine, CPU time alone one that
/// multiplies matrices on two threads), or when its wall time passes [`STALL_LIMIT`].
pub const TIME_LIMIT: Duration = Duration::from_secs(10);
/// Wall time after which a mutant fails however little CPU it used (a stall or a deadlock).
pub const STALL_LIMIT: Duration = Duration::from_secs(60);

/// CPU time used so far by process `pid` (this one when `None`), from `/proc/<pid>/stat` (user
/// and system time in the kernel's fixed 100 ticks a second); zero where there is no `/proc`.
pub fn cpu_time(pid: Option<u32>) -> Duration {
    let path = pid.map_or_else(|| "/proc/self/stat".to_string(), |p| format!("/proc/{p}/stat"));
    let Ok(stat) = std::fs::read_to_string(path) else { return Duration::ZERO };
    // Fields after the command name (which may hold spaces) end in `)`: state is field 3, utime 14.
    let after = stat.rsplit_once(')').map_or("", |(_, rest)| rest);
    let ticks: u64 = after.split_whitespace().skip(11).take(2).filter_map(|f| f.parse::<u64>().ok()).sum();
    Duration::from_millis(ticks * 10)
}

/// Whether a mutant that has run `wall` and used `cpu` is over the limit.
pub fn over_limit(wall: Duration, cpu: Duration) -> bool {
    (wall > TIME_LIMIT && cpu > TIME_LIMIT) || wall > STALL_LIMIT
}

static LIVE: AtomicUsize = AtomicUsize::new(0);
/// Live bytes after the warm-up: per-thread scratch the engine keeps for good (faer's gemm
/// backend holds about 1 GiB of address space per thread that multiplies matrices).
static BASELINE: AtomicUsize = AtomicUsize::new(usize::MAX / 2);
static PEAK: AtomicUsize = AtomicUsize::new(0);
/// Milliseconds since [`epoch`] at which the current mutant started (0: none running).
static STARTED_MS: AtomicU64 = AtomicU64::new(0);
/// This process's CPU time when the current mutant started [ms].
static STARTED_CPU_MS: AtomicU64 = AtomicU64::new(0);
/// Description of the mutant running now (read without allocating by the guards).
static CURRENT: Mutex<String> = Mutex::new(String::new());
/// Live heap when the current mutant began [bytes].
static LIVE_AT_BEGIN: AtomicUsize = AtomicUsize::new(0);
/// The mutant that left the most live heap behind it (a cache or buffer it grew and the engine
/// keeps): bytes and description. A limit crossed later by an innocent mutant names it too.
static GREW_MOST: Mutex<(usize, String)> = Mutex::new((0, String::new()));

fn epoch() -> Instant {
    static EPOCH: std::sync::OnceLock<Instant> = std::sync::OnceLock::new();
    *EPOCH.get_or_init(Instant::now)
}

/// The file holding the mutant being run.
pub fn current_file() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("target").join("fuzz-current.txt")
}

/// Record `description` as the running mutant (file and memory) and start its clock.
pub fn begin(description: &str) {
    let _ = std::fs::write(current_file(), description);
    let text = description.to_string();
    *CURRENT.lock().unwrap_or_else(|e| e.into_inner()) = text;
    STARTED_CPU_MS.store(cpu_time(None).as_millis() as u64, Ordering::SeqCst);
    STARTED_MS.store(epoch().elapsed().as_millis() as u64 + 1, Ordering::SeqCst);
    LIVE_AT_BEGIN.store(LIVE.load(Ordering::SeqCst), Ordering::SeqCst);
}

/// Name the mutant of `seed` as the one running while the mutator makes it: a limit crossed by
/// the mutator itself (a flood of an already long value) then names that seed, not the mutant
/// run before it.
pub fn making(seed: u64) {
    let text = format!("seed={seed:#018x} (while the mutator makes it, before it runs)");
    let _ = std::fs::write(current_file(), &text);
    *CURRENT.lock().unwrap_or_else(|e| e.into_inner()) = text;
}

/// The mutant finished: stop its clock, and remember it if it left more live heap behind than
/// any before it. Returns the live heap it left behind (or freed) [bytes].
pub fn end() -> isize {
    STARTED_MS.store(0, Ordering::SeqCst);
    let (now, then) = (LIVE.load(Ordering::SeqCst), LIVE_AT_BEGIN.load(Ordering::SeqCst));
    let left = now.saturating_sub(then);
    let mut most = GREW_MOST.lock().unwrap_or_else(|e| e.into_inner());
    if left > most.0 {
        let current = CURRENT.lock().unwrap_or_else(|e| e.into_inner()).clone();
        *most = (left, current);
    }
    now as isize - then as isize
}

/// Take the live heap now as the baseline the limit counts from; reset the peak, and the mutant
/// that left the most heap (what the warm-up keeps is in the baseline, not a suspect).
pub fn set_baseline() -> usize {
    let live = LIVE.load(Ordering::SeqCst);
    BASELINE.store(live, Ordering::SeqCst);
    PEAK.store(live, Ordering::SeqCst);
    *GREW_MOST.lock().unwrap_or_else(|e| e.into_inner()) = (0, String::new());
    live
}

/// Live heap now above the baseline [bytes] (negative below it).
pub fn above_baseline() -> isize {
    LIVE.load(Ordering::SeqCst) as isize - BASELINE.load(Ordering::SeqCst) as isize
}

/// Peak live heap above the baseline [bytes].
pub fn peak() -> usize {
    PEAK.load(Ordering::Relaxed).saturating_sub(BASELINE.load(Ordering::Relaxed))
}

/// Print `what` and the running mutant to stderr without allocating, then abort.
fn die(what: &str, amount: usize, unit: &str) -> ! {
    let mut err = std::io::stderr();
    let _ = writeln!(err, "\nfuzz FAILURE: {what} ({amount} {unit})");
    match CURRENT.try_lock() {
        Ok(d) => {
            let _ = writeln!(err, "mutant: {}", d.as_str());
        }
        Err(_) => {
            let _ = writeln!(err, "mutant: see the file below");
        }
    }
    let _ = writeln!(err, "(also in target/fuzz-current.txt)");
    if let Ok(most) = GREW_MOST.try_lock() {
        let _ = writeln!(err, "the mutant that left the most live heap behind ({} bytes): {}", most.0, most.1.as_str());
    }
    std::process::abort()
}

/// Start the watchdog thread.
pub fn start_watchdog() {
    epoch();
    std::thread::spawn(|| {
        loop {
            std::thread::sleep(Duration::from_millis(100));
            let started = STARTED_MS.load(Ordering::SeqCst);
            if started == 0 {
                continue;
            }
            let ms = (epoch().elapsed().as_millis() as u64 + 1).saturating_sub(started);
            let cpu = (cpu_time(None).as_millis() as u64).saturating_sub(STARTED_CPU_MS.load(Ordering::SeqCst));
            if over_limit(Duration::from_millis(ms), Duration::from_millis(cpu)) {
                die("mutant over the time limit of 10 s of wall and CPU time (ms of wall)", ms as usize, "ms");
            }
        }
    });
}

/// [`System`] with a count of live bytes, a peak, and the memory limit.
pub struct Counting;

impl Counting {
    fn grow(&self, bytes: usize) {
        if bytes > MEMORY_LIMIT {
            die("single allocation over 2 GiB", bytes, "bytes");
        }
        let live = LIVE.fetch_add(bytes, Ordering::Relaxed) + bytes;
        let above = live.saturating_sub(BASELINE.load(Ordering::Relaxed));
        if above > MEMORY_LIMIT {
            die("live heap over 2 GiB above the warm-up baseline", above, "bytes");
        }
        PEAK.fetch_max(live, Ordering::Relaxed);
    }
}

// SAFETY: every call is forwarded to `System` with the same arguments; the bookkeeping around it
// only reads and writes atomics.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        self.grow(layout.size());
        // SAFETY: forwarded unchanged.
        unsafe { System.alloc(layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        self.grow(layout.size());
        // SAFETY: forwarded unchanged.
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        LIVE.fetch_sub(layout.size(), Ordering::Relaxed);
        // SAFETY: forwarded unchanged.
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if new_size > MEMORY_LIMIT {
            die("single allocation over 2 GiB", new_size, "bytes");
        }
        if new_size > layout.size() {
            self.grow(new_size - layout.size());
        } else {
            LIVE.fetch_sub(layout.size() - new_size, Ordering::Relaxed);
        }
        // SAFETY: forwarded unchanged.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}
