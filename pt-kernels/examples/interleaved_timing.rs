//! Kernel timings that survive a drifting machine: the paired and the direct P17 kernel, P15, and P17 four at
//! a time, timed in interleaved blocks of 1,000 calls, 300 rounds, the fastest block of each kept. Ratios
//! between kernels measured this way are stable to ~3% on a VM whose speed drifts by 1.6× within minutes,
//! where separate criterion runs are not. `cargo run --release -p pt-kernels --example interleaved_timing`
use std::hint::black_box;
use std::time::Instant;

/// Fastest time per call (s) of `f`, run `calls` times per block.
fn block(best: &mut f64, calls: usize, per_call: usize, mut f: impl FnMut()) {
    let t = Instant::now();
    for _ in 0..calls {
        f();
    }
    *best = best.min(t.elapsed().as_secs_f64() / (calls * per_call) as f64);
}

fn main() {
    // The fixed vectors of the criterion bench (tests/benches/kernels.rs).
    let v: Vec<[f64; 3]> = (0..7)
        .map(|i| {
            let a = i as f64;
            [(1.3 * a).sin() + 0.1, (0.7 * a + 1.0).cos(), 0.3 + 0.1 * a]
        })
        .collect();
    let g4: [f64; 10] = pt_kernels::gram(&v[..4]).try_into().unwrap();
    let g3: [f64; 6] = pt_kernels::gram(&v[..3]).try_into().unwrap();
    let g4x4: [[f64; 10]; 4] =
        std::array::from_fn(|l| pt_kernels::gram(&v[l..l + 4]).try_into().unwrap());
    let mut best = [f64::MAX; 4];
    for _ in 0..300 {
        block(&mut best[0], 1000, 1, || {
            black_box(pt_kernels::propagator_7(black_box(&g4)));
        });
        block(&mut best[1], 1000, 1, || {
            black_box(pt_kernels::generated::propagator_7::<f64>(black_box(&g4)));
        });
        block(&mut best[2], 1000, 1, || {
            black_box(pt_kernels::propagator_5(black_box(&g3)));
        });
        block(&mut best[3], 250, 4, || {
            black_box(pt_kernels::propagator_7_x4(black_box(&g4x4)));
        });
    }
    let [paired, direct, p15, x4] = best;
    println!(
        "P17 paired {:.3} µs, direct {:.3} µs, P15 {:.1} ns, P17 x4 {:.3} µs per configuration; \
         paired/direct {:.3}, paired/P15 {:.2}",
        paired * 1e6,
        direct * 1e6,
        p15 * 1e9,
        x4 * 1e6,
        paired / direct,
        paired / p15
    );
}
