//! Randomized variants of scenes, for recording yarn-level training sequences.
//!
//! Sequence `i` of a recording of `S` scenes with `N` variations each is variation `i mod N`
//! of scene `i / N`; its random draws come from a generator seeded by the recording's seed and
//! `i` alone, so any shard of the sequences (`i mod count == index`, a Slurm array or a
//! Kubernetes Indexed Job) records exactly what the whole recording would. Variation 0 of
//! every scene is the scene as written. The others draw, uniformly and independently:
//! - **handle motions**: every keyframe translation scaled by one factor in `[0.5, 1.5]`;
//! - **obstacle placement**: sphere centres shifted in x and y by up to 10% of the swatch's
//!   size each (planes are kept);
//! - **drop height**: the swatch lifted by up to one tenth of its smaller side (with its
//!   handles, which hold it where it starts), so it falls further onto the obstacles.

use serde::Serialize;
use yarnhom_shell::contact::Obstacle;

use crate::dynamics::Scene;

/// One variant's draws.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Variation {
    /// Sequence index in the recording.
    pub sequence: u64,
    /// The scene's index among the recording's scenes.
    pub scene: usize,
    /// The variation's index within its scene (0: as written).
    pub variation: u64,
    /// Factor on every handle translation.
    pub motion_scale: f64,
    /// Shift of every sphere obstacle's centre in x and y (m).
    pub obstacle_shift_m: [f64; 2],
    /// Lift of the swatch (m).
    pub lift_m: f64,
}

impl Variation {
    /// The draws of sequence `sequence` of a recording with `variations` per scene and `seed`,
    /// on a swatch of `size_m`.
    pub fn draw(sequence: u64, variations: u64, seed: u64, size_m: [f64; 2]) -> Variation {
        let (scene, variation) = ((sequence / variations) as usize, sequence % variations);
        let mut random = SplitMix64::new(seed ^ sequence.wrapping_mul(0x9E37_79B9_7F4A_7C15));
        let mut uniform = |lo: f64, hi: f64| {
            if variation == 0 { (lo + hi) / 2.0 } else { lo + (hi - lo) * random.next_unit() }
        };
        let motion_scale = uniform(0.5, 1.5);
        let obstacle_shift_m = [uniform(-0.1, 0.1) * size_m[0], uniform(-0.1, 0.1) * size_m[1]];
        let lift_m = if variation == 0 { 0.0 } else { uniform(0.0, 0.1) * size_m[0].min(size_m[1]) };
        Variation { sequence, scene, variation, motion_scale, obstacle_shift_m, lift_m }
    }

    /// The shell scene with this variant's motions and obstacles.
    pub fn apply_to_scene(&self, scene: &yarnhom_shell::Scene) -> yarnhom_shell::Scene {
        let scale = |keys: &Vec<(f64, [f64; 3])>| {
            keys.iter().map(|&(t, d)| (t, d.map(|x| x * self.motion_scale))).collect()
        };
        let shift = |o: &Obstacle| match *o {
            Obstacle::Sphere { center, radius } => {
                let [dx, dy] = self.obstacle_shift_m;
                Obstacle::Sphere { center: [center[0] + dx, center[1] + dy, center[2]], radius }
            }
            other => other,
        };
        yarnhom_shell::Scene {
            motions: scene.motions.iter().map(scale).collect(),
            obstacles: scene.obstacles.iter().map(shift).collect(),
            ..scene.clone()
        }
    }

    /// The placed yarn-level scene lifted by this variant's drop height.
    pub fn lift(&self, mut placed: Scene) -> Scene {
        for yarn in &mut placed.yarns {
            yarn.positions_m.iter_mut().for_each(|p| p[2] += self.lift_m);
        }
        placed
    }
}

/// The sequences of a recording of `total` sequences that shard `index` of `count` records.
pub fn shard_sequences(total: u64, index: u64, count: u64) -> impl Iterator<Item = u64> {
    (0..total).filter(move |i| i % count == index)
}

/// SplitMix64 (Steele et al. 2014): a small, fast generator whose streams for different seeds
/// are independent enough for drawing scene variants.
struct SplitMix64(u64);

impl SplitMix64 {
    fn new(seed: u64) -> Self {
        SplitMix64(seed)
    }

    /// A uniform draw in `[0, 1)` (53 random bits).
    fn next_unit(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn draws_depend_on_the_seed_and_sequence_only_and_stay_in_their_ranges() {
        let size = [0.1, 0.05];
        let a = Variation::draw(7, 4, 42, size);
        assert_eq!(a, Variation::draw(7, 4, 42, size), "reproducible");
        assert_ne!(a, Variation::draw(7, 4, 43, size), "the seed matters");
        assert_eq!((a.scene, a.variation), (1, 3));
        for i in 0..200 {
            let v = Variation::draw(i, 5, 1, size);
            assert!((0.5..=1.5).contains(&v.motion_scale));
            assert!(v.obstacle_shift_m[0].abs() <= 0.01 && v.obstacle_shift_m[1].abs() <= 0.005);
            assert!((0.0..=0.005).contains(&v.lift_m));
            if v.variation == 0 {
                assert_eq!(
                    (v.motion_scale, v.obstacle_shift_m, v.lift_m),
                    (1.0, [0.0, 0.0], 0.0),
                    "as written"
                );
            }
        }
    }

    #[test]
    fn shards_partition_the_sequences() {
        let mut all: Vec<u64> = (0..3).flat_map(|k| shard_sequences(10, k, 3)).collect();
        all.sort_unstable();
        assert_eq!(all, (0..10).collect::<Vec<_>>());
    }

    #[test]
    fn a_variant_scales_the_motions_and_shifts_the_spheres() {
        let scene = yarnhom_shell::Scene::builtin("drape").expect("a built-in");
        let v = Variation {
            motion_scale: 2.0,
            obstacle_shift_m: [0.01, -0.02],
            ..Variation::draw(1, 2, 0, [0.1, 0.1])
        };
        let varied = v.apply_to_scene(&scene);
        let Obstacle::Sphere { center, .. } = varied.obstacles[0] else { panic!("the drape's sphere") };
        assert_eq!(center, [0.01, -0.02, -0.04]);
        let stretch = v.apply_to_scene(&yarnhom_shell::Scene::builtin("stretch-x").expect("a built-in"));
        assert_eq!(stretch.motions[1][1].1, [0.07, 0.0, 0.0]);
    }
}
