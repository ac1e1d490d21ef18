//! The bundled Gough-Stewart's generated `inverse_dynamics` (and the full-inertia variant's), plain
//! and with `fma`: random regular states near home written to `data/VARIANT.txt` for
//! `gs_bench.cpp` (the Pinocchio routes check their forces against these), and the generated
//! functions timed as `../src/main.rs` times the arms (median of 31 batches, ns per call).
#[allow(dead_code)] // the modules' other items
mod gs {
    include!(concat!(env!("OUT_DIR"), "/all.rs"));
}

/// Number of states.
const S: usize = 256;
/// Passes over the states per timed batch.
const PASSES: usize = 2;

struct Rng(u64);
impl Rng {
    /// splitmix64, uniform in [-h, h].
    fn u(&mut self, h: f64) -> f64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
        h * (2.0 * ((z >> 11) as f64 / (1u64 << 53) as f64) - 1.0)
    }
}

type State = ([f64; 7], [f64; 6], [f64; 6]);

/// Platform within ±0.1 m and a rotation vector within ±0.2 rad of home; u, ud within ±1, ±2.
fn states(home: &[f64; 7], seed: u64) -> Vec<State> {
    let mut r = Rng(seed);
    (0..S)
        .map(|_| {
            let mut x = *home;
            for k in 0..3 {
                x[k] += r.u(0.1);
            }
            let rv = [r.u(0.2), r.u(0.2), r.u(0.2)];
            let a = (rv[0] * rv[0] + rv[1] * rv[1] + rv[2] * rv[2]).sqrt();
            let (s, c) = (0.5 * a).sin_cos();
            x[3] = c;
            for k in 0..3 {
                x[4 + k] = s * rv[k] / a;
            }
            let u: [f64; 6] = std::array::from_fn(|_| r.u(1.0));
            let ud: [f64; 6] = std::array::from_fn(|_| r.u(2.0));
            (x, u, ud)
        })
        .collect()
}

#[path = "../../src/rel.rs"]
mod rel;
use rel::rel;

#[repr(C)]
struct Timespec {
    sec: i64,
    nsec: i64,
}
unsafe extern "C" {
    fn clock_gettime(clock: i32, t: *mut Timespec) -> i32;
}
/// The calling thread's CPU time (Linux `CLOCK_THREAD_CPUTIME_ID`), ns.
fn cpu_ns() -> f64 {
    let mut t = Timespec { sec: 0, nsec: 0 };
    // SAFETY: a valid pointer to a `struct timespec` (x86-64 Linux layout).
    unsafe { clock_gettime(3, &mut t) };
    t.sec as f64 * 1e9 + t.nsec as f64
}

/// Median over 101 batches (each `PASSES` times over the states) of ns per call: wall-clock and
/// the thread's CPU time (as gs_bench.cpp; the machine is shared, and the CPU time leaves out
/// the time other processes held the core).
fn time(st: &[State], f: &dyn Fn(&State) -> f64) -> (f64, f64) {
    let (mut tw, mut tc) = (Vec::new(), Vec::new());
    for _ in 0..101 {
        let c0 = cpu_ns();
        let t0 = std::time::Instant::now();
        let mut sink = 0.0;
        for _ in 0..PASSES {
            for s in st {
                sink += f(std::hint::black_box(s));
            }
        }
        std::hint::black_box(sink);
        let n = (st.len() * PASSES) as f64;
        tw.push(t0.elapsed().as_nanos() as f64 / n);
        tc.push((cpu_ns() - c0) / n);
    }
    tw.sort_by(f64::total_cmp);
    tc.sort_by(f64::total_cmp);
    (tw[50], tc[50])
}

/// The `inverse_dynamics` row of a module's operation-count header.
fn flops(header: &str) -> String {
    header
        .lines()
        .find(|l| l.starts_with("// | inverse_dynamics |"))
        .map(|l| l[3..].to_string())
        .unwrap_or_default()
}

macro_rules! variant {
    ($v:ident, $seed:expr) => {{
        use gs::$v::{fma as f, plain as g};
        std::fs::create_dir_all("data").unwrap();
        let all = states(&g::HOME, $seed);
        let mut kept = Vec::new();
        let mut lines = String::new();
        let mut efma = 0.0f64;
        for s in &all {
            let (x, u, ud) = s;
            // Regular states only: the generated code's guards (leg, parallel singularity) pass.
            let (Ok(tau), Ok(q)) = (g::inverse_dynamics(x, u, ud), g::inverse_kinematics(x)) else { continue };
            efma = efma.max(rel(&f::inverse_dynamics(x, u, ud).unwrap(), &tau));
            let nums: Vec<String> = x.iter().chain(u).chain(ud).chain(&q).chain(&tau).map(|v| format!("{v:e}")).collect();
            lines.push_str(&nums.join(" "));
            lines.push('\n');
            kept.push(*s);
        }
        std::fs::write(concat!("data/", stringify!($v), ".txt"), lines).unwrap();
        let tp = time(&kept, &|(x, u, ud)| std::hint::black_box(g::inverse_dynamics(x, u, ud)).map(|t| t[0]).unwrap_or(0.0));
        let tf = time(&kept, &|(x, u, ud)| std::hint::black_box(f::inverse_dynamics(x, u, ud)).map(|t| t[0]).unwrap_or(0.0));
        println!("flops {} plain {}", stringify!($v), flops(g::HEADER));
        println!("flops {} fma {}", stringify!($v), flops(f::HEADER));
        println!(
            "gs {} states {} of {}  fma vs plain {:.1e}  ns wall: plain {:.1} fma {:.1}  cpu: plain {:.1} fma {:.1}",
            stringify!($v), kept.len(), all.len(), efma, tp.0, tf.0, tp.1, tf.1
        );
    }};
}

fn main() {
    variant!(bundled, 24);
    variant!(full, 25);
}
