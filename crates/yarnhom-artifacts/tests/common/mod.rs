//! Proptest strategies for valid artifacts of every kind.
#![allow(dead_code, missing_docs)]

use proptest::prelude::*;
use yarnhom_artifacts::{
    Fabric, Grid, GridSample, GridShard, GridTerm, Pattern, RestState, RveSolve, StrainSample, Yarn,
    YarnMechanics, YarnModel,
};

fn finite(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    lo..hi
}

fn unit_vector() -> impl Strategy<Value = [f64; 3]> {
    (0.0..std::f64::consts::PI, 0.0..std::f64::consts::TAU)
        .prop_map(|(theta, phi): (f64, f64)| [theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos()])
}

fn yarn_shapes() -> impl Strategy<Value = Vec<usize>> {
    prop::collection::vec(3usize..9, 1..4)
}

/// A valid pattern: random positions inside the tile, periodic offsets whose sum is never zero.
pub fn pattern() -> impl Strategy<Value = Pattern> {
    (yarn_shapes(), finite(1e-3, 3e-2), finite(1e-3, 3e-2), finite(1e-5, 2e-3), any::<bool>(), any::<bool>())
        .prop_flat_map(|(shape, px, py, radius, with_rest, knit)| {
            let n: usize = shape.iter().sum();
            let positions = prop::collection::vec(
                (
                    finite(-px / 2.0, px / 2.0),
                    finite(-py / 2.0, py / 2.0),
                    finite(-radius * 3.0, radius * 3.0),
                )
                    .prop_map(|(x, y, z)| [x, y, z]),
                n,
            );
            let twists = prop::collection::vec(finite(-3.0, 3.0), n);
            let offsets = prop::collection::vec((-1i32..=1, -1i32..=1).prop_map(|(a, b)| [a, b]), n);
            let rest = rest_state(n);
            (
                Just(shape),
                Just([px, py]),
                Just(radius),
                positions,
                twists,
                offsets,
                rest,
                Just(with_rest),
                Just(knit),
            )
        })
        .prop_map(|(shape, period, radius, positions, twists, offsets, rest, with_rest, knit)| {
            let mut yarns = Vec::new();
            let mut start = 0;
            for len in shape {
                let mut edge_offsets = offsets[start..start + len].to_vec();
                let sum = edge_offsets.iter().fold([0, 0], |a, o| [a[0] + o[0], a[1] + o[1]]);
                if sum == [0, 0] {
                    edge_offsets[len - 1][0] =
                        if edge_offsets[len - 1][0] == 1 { 0 } else { edge_offsets[len - 1][0] + 1 };
                }
                yarns.push(Yarn {
                    radius_m: radius,
                    vertices: (start as u32..(start + len) as u32).collect(),
                    edge_offsets,
                });
                start += len;
            }
            Pattern {
                name: "random".into(),
                fabric: if knit { Fabric::Knit } else { Fabric::Woven },
                period_m: period,
                // Shift vertex k by k * 1e-3 periods so that shrinking never makes edges vanish.
                positions_m: positions
                    .iter()
                    .enumerate()
                    .map(|(k, x)| [x[0] + k as f64 * 1e-3 * period[0], x[1], x[2]])
                    .collect(),
                edge_twist_rad: twists,
                yarns,
                rest: with_rest.then_some(rest),
                origin: "proptest".into(),
            }
        })
}

fn rest_state(n: usize) -> impl Strategy<Value = RestState> {
    (
        prop::collection::vec(finite(1e-5, 1e-2), n),
        prop::collection::vec((finite(-2.0, 2.0), finite(-2.0, 2.0)).prop_map(|(a, b)| [a, b]), n),
        prop::collection::vec(finite(-1.0, 1.0), n),
        prop::collection::vec(unit_vector(), n),
        prop::collection::vec(finite(-1.0, 1.0), n),
    )
        .prop_map(|(l, k, t, d, rt)| RestState {
            edge_length_m: l,
            vertex_curvature: k,
            vertex_twist_rad: t,
            edge_reference_director: d,
            vertex_reference_twist_rad: rt,
        })
}

/// A valid yarn model of either family.
pub fn yarn_model() -> impl Strategy<Value = YarnModel> {
    let rod = (finite(1e3, 1e9), finite(1e3, 1e9), finite(1e-4, 10.0), finite(1e-1, 1e4)).prop_map(
        |(e, g, gamma, k)| YarnMechanics::ElasticRod {
            youngs_modulus_pa: e,
            shear_modulus_pa: g,
            gamma,
            contact_stiffness_kg_s2: k,
        },
    );
    let biphasic = (
        finite(1e-3, 1.0),
        finite(1.0, 1e3),
        finite(0.0, 0.2),
        finite(1e-12, 1e-6),
        finite(1e-4, 1e-3),
        finite(1e-2, 1e2),
        finite(1e-2, 1e3),
    )
        .prop_map(|(f1, ks2, eps, kb, r1, kc1, kc2)| YarnMechanics::Biphasic {
            k_s1_n: f1 * ks2,
            k_s2_n: ks2,
            eps_bar: eps,
            k_b_nm2: kb,
            r1_m: r1,
            k_c1_n_m: kc1,
            r2_m: 0.25 * r1,
            k_c2_n_m: kc2,
        });
    (finite(1e-5, 1e-2), finite(10.0, 2e3), prop_oneof![rod, biphasic]).prop_map(|(r, rho, mechanics)| {
        YarnModel { name: "random".into(), radius_m: r, density_kg_m3: rho, mechanics }
    })
}

/// A valid tile solve, converged or not.
pub fn rve_solve() -> impl Strategy<Value = RveSolve> {
    (prop::collection::vec(-0.5f64..2.0, 5), any::<bool>(), 1usize..20, any::<bool>()).prop_flat_map(
        |(s, converged, n, stress)| {
            (
                Just((s, converged, stress)),
                prop::collection::vec(prop::array::uniform3(-0.01f64..0.01), n),
                prop::collection::vec(-3.0f64..3.0, n),
                0.0f64..10.0,
                prop::array::uniform5(-10.0f64..10.0),
            )
                .prop_map(|((s, converged, stress), positions, twists, energy, st)| RveSolve {
                    pattern: "p".into(),
                    model: "m".into(),
                    strain: StrainSample {
                        sx: s[0],
                        sa: s[1] / 3.0,
                        sy: s[2],
                        kx: s[3] * 50.0,
                        ky: s[4] * 50.0,
                    },
                    converged,
                    stop_reason: if converged { "converged".into() } else { "iteration_limit".into() },
                    energy_density_j_m2: converged.then_some(energy),
                    stress: (converged && stress).then_some(st),
                    stress_fd: (converged && stress).then_some(st.map(|x| x * 1.001)),
                    iterations: 7,
                    gradient_ratio: 1e-6,
                    seconds: 0.5,
                    positions_m: positions,
                    edge_twist_rad: twists,
                })
        },
    )
}

/// How one sample of a plan came out, and whether the grid keeps it.
#[derive(Debug, Clone, Copy)]
pub struct Outcome {
    pub converged: bool,
    pub energy: f64,
    pub stress: Option<[f64; 5]>,
    pub keep: bool,
}

/// The `(term, index)` of every sample of a plan, sorted.
pub fn plan(axes: &[Vec<f64>; 5], terms: &[Vec<u8>]) -> Vec<(u32, [u32; 2])> {
    let mut out = Vec::new();
    for (t, term) in terms.iter().enumerate() {
        let len = |k: usize| term.get(k).map_or(1, |&a| axes[a as usize].len() as u32);
        for i in 0..len(0) {
            for j in 0..len(1) {
                out.push((t as u32, [i, j]));
            }
        }
    }
    out
}

/// A valid grid over a plan: sample `k` of the plan comes out as `outcomes[k % len]` (and is
/// left out unless kept); `vertices` adds an equilibrium geometry of that many vertices.
pub fn build_grid(
    axes: [Vec<f64>; 5],
    terms: Vec<Vec<u8>>,
    outcomes: &[Outcome],
    vertices: Option<usize>,
) -> Grid {
    let mut grid = Grid {
        pattern: "rib".into(),
        model: "rib".into(),
        terms: terms
            .iter()
            .map(|t| GridTerm {
                axes: t.clone(),
                values: t.iter().map(|&a| axes[a as usize].clone()).collect(),
            })
            .collect(),
        shard: None,
        samples: Vec::new(),
    };
    for (k, (term, index)) in plan(&axes, &terms).into_iter().enumerate() {
        let o = outcomes[k % outcomes.len()];
        if !o.keep {
            continue;
        }
        let strain = grid.strain_at(term as usize, index).expect("in the plan");
        let geometry = vertices.map(|v| {
            let positions =
                (0..v).map(|i| [k as f64 * 1e-3, i as f64 * 0.1 + 0.2, -(i as f64) / 3.0]).collect();
            (positions, (0..v).map(|i| (i + k) as f64 / 7.0).collect())
        });
        let (positions_m, edge_twist_rad) = geometry.unzip();
        grid.samples.push(GridSample {
            term,
            index,
            strain,
            converged: o.converged,
            stop_reason: if o.converged { "converged".into() } else { "iteration_limit".into() },
            energy_density_j_m2: o.converged.then_some(o.energy),
            stress: o.stress.filter(|_| o.converged),
            iterations: k as u32 % 17,
            positions_m,
            edge_twist_rad,
        });
    }
    grid
}

/// A fixed grid of four terms (two 1D, two 2D) with every sample, a few not converged, stress on
/// some, awkward floats.
pub fn sample_grid(vertices: Option<usize>) -> Grid {
    let axes = [
        vec![-0.1, 0.0, 0.1 + 0.2],
        vec![-0.3, -0.0, f64::MIN_POSITIVE / 4.0, 0.3],
        vec![0.0, 0.5],
        vec![-10.0, 0.0, 1.0 / 3.0],
        vec![0.0, 5.0],
    ];
    let outcomes: Vec<Outcome> = (0..7)
        .map(|k| Outcome {
            converged: k != 3,
            energy: 0.1 + k as f64 * 0.37,
            stress: (k % 2 == 0).then_some([k as f64, -0.5, 1e-300, 2.0, -0.0]),
            keep: true,
        })
        .collect();
    build_grid(axes, vec![vec![0], vec![1], vec![0, 2], vec![3, 4]], &outcomes, vertices)
}

fn axis_values() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::btree_set(-1000i32..1000, 0..5).prop_map(|set| {
        let mut values: Vec<f64> = set.into_iter().map(|x| f64::from(x) * 1e-3).collect();
        values.push(0.0);
        values.sort_by(f64::total_cmp);
        values.dedup();
        values
    })
}

fn outcome() -> impl Strategy<Value = Outcome> {
    (
        any::<bool>(),
        0.0f64..10.0,
        prop::option::of(prop::array::uniform5(-10.0f64..10.0)),
        prop::bool::weighted(0.8),
    )
        .prop_map(|(converged, energy, stress, keep)| Outcome { converged, energy, stress, keep })
}

/// A valid grid: random axes and terms, some samples left out, maybe a shard and a geometry.
pub fn grid() -> impl Strategy<Value = Grid> {
    let all_terms: Vec<Vec<u8>> =
        (0..5u8).map(|a| vec![a]).chain((0..5u8).flat_map(|a| (a + 1..5).map(move |b| vec![a, b]))).collect();
    (
        prop::array::uniform5(axis_values()),
        prop::sample::subsequence(all_terms, 1..6),
        prop::collection::vec(outcome(), 1..40),
        prop::option::of(1usize..6),
        prop::option::of((0u32..4, 1u32..4)),
    )
        .prop_map(|(axes, terms, outcomes, vertices, shard)| {
            let mut grid = build_grid(axes, terms, &outcomes, vertices);
            grid.shard = shard.map(|(i, extra)| GridShard { index: i, count: i + extra });
            grid
        })
}
