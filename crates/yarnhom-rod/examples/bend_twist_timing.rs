//! Time the bend-twist element's energy, gradient and Hessian: closed form against dual numbers.
//!
//! `cargo run --release -p yarnhom-rod --example bend_twist_timing`
//!
//! Prints wall-clock and, where Linux's `/proc/thread-self/schedstat` is readable, CPU time per
//! call (the latter is what to compare on a busy machine).

use std::hint::black_box;
use std::time::Instant;

use nalgebra::{SMatrix, SVector};
use yarnhom_rod::{BendTwist, BendTwistDofs, BendTwistReference, EdgeFrame};

const CALLS: u32 = 100_000;

/// CPU time of this thread so far (ns).
fn cpu_time_ns() -> Option<f64> {
    let schedstat = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
    schedstat.split_whitespace().next()?.parse().ok()
}

/// Wall-clock and CPU nanoseconds per call of `f`, over [`CALLS`] calls at slightly different
/// configurations.
fn nanoseconds_per_call(
    q: &BendTwistDofs,
    f: impl Fn(&BendTwistDofs) -> (f64, SVector<f64, 11>, SMatrix<f64, 11, 11>),
) -> (f64, Option<f64>) {
    let (start, start_cpu) = (Instant::now(), cpu_time_ns());
    let mut sum = 0.0;
    for i in 0..CALLS {
        let mut qi = *q;
        qi[4] += 1e-9 * f64::from(i);
        sum += f(black_box(&qi)).2[(3, 7)];
    }
    black_box(sum);
    let wall = start.elapsed().as_nanos() as f64 / f64::from(CALLS);
    let cpu = start_cpu.zip(cpu_time_ns()).map(|(a, b)| (b - a) / f64::from(CALLS));
    (wall, cpu)
}

fn main() {
    let element = BendTwist {
        bend_stiffness_nm2: [2.0, 3.0],
        twist_stiffness_nm2: 1.5,
        rest_curvature: [0.2, -0.1],
        rest_twist_rad: 0.05,
        rest_length_sum_m: 2.0,
    };
    let frames =
        [EdgeFrame::new([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]), EdgeFrame::new([0.8, 0.6, 0.1], [0.0, 0.0, 1.0])];
    let reference = BendTwistReference { frames, reference_twist_rad: 0.0 };
    // Away from the reference configuration, twisted.
    let q = BendTwistDofs::from_column_slice(&[0.0, 0.0, 0.0, 1.0, 0.05, 0.0, 1.8, 0.7, 0.15, 0.1, -0.2]);
    let runs = [
        (
            "dual numbers",
            nanoseconds_per_call(&q, |q| element.energy_gradient_hessian_autodiff(&reference, q)),
        ),
        ("closed form", nanoseconds_per_call(&q, |q| element.energy_gradient_hessian(&reference, q))),
    ];
    for (name, (wall, cpu)) in runs {
        let cpu = cpu.map_or(String::new(), |c| format!(", {c:.0} ns/call CPU"));
        println!("{name:>12}: {wall:.0} ns/call wall{cpu}");
    }
    let ratio = |i: usize| runs[i].1.1.unwrap_or(runs[i].1.0);
    println!("speed-up: {:.1}x", ratio(0) / ratio(1));
}
