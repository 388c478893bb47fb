//! Particle swarm optimization over a box (Bonyadi and Michalewicz 2017), the global step of the
//! yarn-level estimation (thesis Sec. 6.5.3: 64 particles, 10 steps, inertia decaying from 0.9 to
//! 0.1, heuristic repulsion).
//!
//! Positions live in the unit cube (each coordinate scaled by its bounds). Each generation's
//! particles are evaluated in parallel. Repulsion: a particle that comes within
//! [`SwarmSettings::repulsion_radius`] of a better particle is pushed away from it, so the swarm
//! does not collapse onto one point before the last steps. The random stream is a fixed
//! function of the seed, so a run is reproducible; shards (independent sub-swarms) use
//! different seeds.

use rayon::prelude::*;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Swarm settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SwarmSettings {
    /// Particles.
    pub particles: usize,
    /// Generations (velocity updates).
    pub generations: usize,
    /// Inertia weight at the first and last generation (decaying linearly).
    pub inertia: (f64, f64),
    /// Pull towards a particle's own best.
    pub cognitive: f64,
    /// Pull towards the swarm's best.
    pub social: f64,
    /// Distance (in the unit cube) below which a particle is repelled from a better one.
    pub repulsion_radius: f64,
    /// Seed of the random stream.
    pub seed: u64,
}

impl Default for SwarmSettings {
    fn default() -> Self {
        SwarmSettings {
            particles: 64,
            generations: 10,
            inertia: (0.9, 0.1),
            cognitive: 1.5,
            social: 1.5,
            repulsion_radius: 0.05,
            seed: 1,
        }
    }
}

impl SwarmSettings {
    /// Shard `k` of `n` independent sub-swarms of these settings: `n` times fewer particles (at
    /// least one) and the seed offset by `7919 k`, so the shards search apart.
    pub fn shard(self, k: u32, n: u32) -> Self {
        SwarmSettings {
            particles: (self.particles / n as usize).max(1),
            seed: self.seed.wrapping_add(u64::from(k) * 7919),
            ..self
        }
    }
}

/// The result of a swarm run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
pub struct SwarmReport {
    /// Best point found (in the problem's coordinates).
    pub best: Vec<f64>,
    /// Its cost.
    pub best_cost: f64,
    /// Best cost after the initial generation and after each update.
    pub history: Vec<f64>,
    /// Objective evaluations.
    pub evaluations: usize,
    /// Evaluations that failed (counted as infinite cost).
    pub failures: usize,
}

/// A splitmix64 stream of uniform numbers in `[0, 1)`.
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Minimize `cost` over the box `bounds`; `None` costs are failures. The first particles start
/// at `seeds` (points in the box, e.g. a nested model's optimum; at most one per particle), the
/// others at random. `progress` sees the generation and the best cost after it.
pub fn minimize<F>(
    cost: F,
    bounds: &[(f64, f64)],
    settings: &SwarmSettings,
    seeds: &[Vec<f64>],
    progress: &(dyn Fn(usize, f64) + Sync),
) -> SwarmReport
where
    F: Fn(&[f64]) -> Option<f64> + Sync,
{
    let mut random = Uniform(settings.seed);
    let to_problem =
        |u: &[f64]| -> Vec<f64> { u.iter().zip(bounds).map(|(x, (lo, hi))| lo + x * (hi - lo)).collect() };
    let evaluate = |points: &[Vec<f64>]| -> Vec<f64> {
        points
            .par_iter()
            .map(|u| cost(&to_problem(u)).filter(|c| c.is_finite()).unwrap_or(f64::INFINITY))
            .collect()
    };
    let mut report = SwarmReport {
        best: Vec::new(),
        best_cost: f64::INFINITY,
        history: Vec::new(),
        evaluations: 0,
        failures: 0,
    };
    let (position, velocity) = Swarm::start(bounds, settings.particles, seeds, &mut random);
    let costs = evaluate(&position);
    report.count(&costs);
    let mut swarm = Swarm::new(position, velocity, costs);
    report.history.push(swarm.best_cost());
    progress(0, swarm.best_cost());
    for generation in 1..=settings.generations {
        swarm.fly(settings, generation, &mut random);
        let costs = evaluate(&swarm.position);
        report.count(&costs);
        swarm.record(costs);
        report.history.push(swarm.best_cost());
        progress(generation, swarm.best_cost());
    }
    report.best = to_problem(&swarm.own_best[swarm.best]);
    report.best_cost = swarm.best_cost();
    report
}

impl SwarmReport {
    /// Count a generation's evaluations and failures.
    fn count(&mut self, costs: &[f64]) {
        self.evaluations += costs.len();
        self.failures += costs.iter().filter(|c| c.is_infinite()).count();
    }
}

/// The particles in the unit cube: where they are, how they move, the cost where they are, and
/// the best point each has seen.
struct Swarm {
    position: Vec<Vec<f64>>,
    velocity: Vec<Vec<f64>>,
    costs: Vec<f64>,
    own_best: Vec<Vec<f64>>,
    own_cost: Vec<f64>,
    /// The particle with the lowest own cost.
    best: usize,
}

impl Swarm {
    /// Starting positions (random, the first ones at `seeds`, mapped into the cube) and
    /// velocities (random, up to 0.1 per coordinate), in the random stream's order.
    fn start(
        bounds: &[(f64, f64)],
        particles: usize,
        seeds: &[Vec<f64>],
        random: &mut Uniform,
    ) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
        let dim = bounds.len();
        let mut position: Vec<Vec<f64>> =
            (0..particles).map(|_| (0..dim).map(|_| random.next()).collect()).collect();
        for (p, seed) in position.iter_mut().zip(seeds) {
            *p =
                seed.iter().zip(bounds).map(|(x, (lo, hi))| ((x - lo) / (hi - lo)).clamp(0.0, 1.0)).collect();
        }
        let velocity: Vec<Vec<f64>> =
            (0..particles).map(|_| (0..dim).map(|_| 0.2 * (random.next() - 0.5)).collect()).collect();
        (position, velocity)
    }

    /// The swarm at its first evaluation.
    fn new(position: Vec<Vec<f64>>, velocity: Vec<Vec<f64>>, costs: Vec<f64>) -> Self {
        let (own_best, own_cost) = (position.clone(), costs.clone());
        let best = best_of(&own_cost);
        Self { position, velocity, costs, own_best, own_cost, best }
    }

    fn best_cost(&self) -> f64 {
        self.own_cost[self.best]
    }

    /// One velocity update of every particle (inertia decaying linearly over the generations,
    /// pulls towards its own and the swarm's best, repulsion), then the move, reflected at the
    /// walls of the cube.
    fn fly(&mut self, settings: &SwarmSettings, generation: usize, random: &mut Uniform) {
        let t = (generation - 1) as f64 / (settings.generations.max(2) - 1) as f64;
        let inertia = settings.inertia.0 + (settings.inertia.1 - settings.inertia.0) * t;
        let dim = self.position.first().map_or(0, Vec::len);
        for p in 0..settings.particles {
            for k in 0..dim {
                let (r1, r2) = (random.next(), random.next());
                self.velocity[p][k] = inertia * self.velocity[p][k]
                    + settings.cognitive * r1 * (self.own_best[p][k] - self.position[p][k])
                    + settings.social * r2 * (self.own_best[self.best][k] - self.position[p][k]);
            }
            repel(p, &mut self.velocity, &self.position, &self.costs, settings.repulsion_radius);
            for k in 0..dim {
                let x = self.position[p][k] + self.velocity[p][k];
                // Reflect at the walls of the cube.
                self.position[p][k] = if x < 0.0 {
                    -x
                } else if x > 1.0 {
                    2.0 - x
                } else {
                    x
                }
                .clamp(0.0, 1.0);
            }
        }
    }

    /// The costs at the new positions: each particle keeps its best point, and the swarm its
    /// best particle.
    fn record(&mut self, costs: Vec<f64>) {
        self.costs = costs;
        for p in 0..self.position.len() {
            if self.costs[p] < self.own_cost[p] {
                self.own_cost[p] = self.costs[p];
                self.own_best[p] = self.position[p].clone();
            }
        }
        self.best = best_of(&self.own_cost);
    }
}

/// The index of the lowest cost (the first of equals).
fn best_of(own_cost: &[f64]) -> usize {
    own_cost.iter().enumerate().fold(0, |b, (i, c)| if *c < own_cost[b] { i } else { b })
}

/// Push particle `p` away from every better particle closer than `radius`: a velocity away
/// from it of the size of the overlap.
fn repel(p: usize, velocity: &mut [Vec<f64>], position: &[Vec<f64>], costs: &[f64], radius: f64) {
    for q in 0..position.len() {
        if q == p || costs[q] >= costs[p] {
            continue;
        }
        let away: Vec<f64> = position[p].iter().zip(&position[q]).map(|(a, b)| a - b).collect();
        let distance = away.iter().map(|x| x * x).sum::<f64>().sqrt();
        if distance < radius && distance > 0.0 {
            let push = (radius - distance) / distance;
            velocity[p].iter_mut().zip(&away).for_each(|(v, a)| *v += push * a);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_swarm_finds_the_global_minimum_of_a_multimodal_function() {
        // Rastrigin in 2D on [-5, 5]² (minimum 0 at the origin, 120 local minima about 1 apart, the
        // nearest ones at cost 1): the swarm must end in the global basin.
        let rastrigin = |x: &[f64]| {
            Some(x.iter().map(|v| v * v - 10.0 * (2.0 * std::f64::consts::PI * v).cos() + 10.0).sum::<f64>())
        };
        let settings = SwarmSettings { particles: 64, generations: 40, ..SwarmSettings::default() };
        let report = minimize(rastrigin, &[(-5.0, 5.0); 2], &settings, &[], &|_, _| {});
        assert!(report.best_cost < 0.5, "{report:?}");
        assert_eq!(report.evaluations, 64 * 41);
        assert!(report.history.windows(2).all(|w| w[1] <= w[0]), "the best never gets worse");
    }

    #[test]
    fn failed_evaluations_are_counted_and_avoided() {
        let cost = |x: &[f64]| if x[0] < 0.0 { None } else { Some((x[0] - 0.5).powi(2)) };
        let report = minimize(cost, &[(-1.0, 1.0)], &SwarmSettings::default(), &[], &|_, _| {});
        assert!(report.failures > 0);
        assert!((report.best[0] - 0.5).abs() < 0.05, "{report:?}");
    }

    #[test]
    fn shards_split_the_particles_and_offset_the_seed() {
        let settings = SwarmSettings { particles: 64, seed: 5, ..SwarmSettings::default() };
        let shard = settings.shard(3, 4);
        assert_eq!((shard.particles, shard.seed), (16, 5 + 3 * 7919));
        assert_eq!(SwarmSettings { particles: 3, ..settings }.shard(0, 4).particles, 1);
        assert_eq!(SwarmSettings { seed: u64::MAX, ..settings }.shard(1, 2).seed, 7918);
    }
}
