//! Handles: sets of vertices moved by prescribed rigid translations, keyframed and piecewise
//! linear in time. Their positions are Dirichlet conditions: eliminated from the Newton solve,
//! not penalized.

use super::input::InputError;

/// A translation at a time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Keyframe {
    /// Time (s).
    pub time_s: f64,
    /// Translation of the handle's vertices from their initial positions (m).
    pub translation_m: [f64; 3],
}

/// Vertices (global indices) whose positions are `x(t) = x(0) + T(t)`, `x(0)` those the
/// simulation starts from and `T` the keyframes' translation: linear between keyframes,
/// constant before the first and after the last. Keyframes normally start with `T = 0`; a
/// jump at the start would move the handle in the first step.
#[derive(Debug, Clone, PartialEq)]
pub struct Handle {
    /// The vertices held (global indices).
    pub vertices: Vec<usize>,
    /// Keyframes, times strictly increasing, at least one.
    pub keyframes: Vec<Keyframe>,
}

impl Handle {
    /// Vertices held where they start.
    pub fn fixed(vertices: Vec<usize>) -> Handle {
        Handle { vertices, keyframes: vec![Keyframe { time_s: 0.0, translation_m: [0.0; 3] }] }
    }

    /// The translation `T(t)` at `time_s`.
    pub fn translation_at(&self, time_s: f64) -> [f64; 3] {
        let after = self.keyframes.partition_point(|k| k.time_s <= time_s);
        match (after.checked_sub(1).and_then(|i| self.keyframes.get(i)), self.keyframes.get(after)) {
            (Some(a), Some(b)) => {
                let s = (time_s - a.time_s) / (b.time_s - a.time_s);
                std::array::from_fn(|k| a.translation_m[k] + s * (b.translation_m[k] - a.translation_m[k]))
            }
            (Some(k), None) | (None, Some(k)) => k.translation_m,
            (None, None) => [0.0; 3],
        }
    }

    /// Check the keyframes (finite, at least one, times strictly increasing) and the vertices
    /// (below `vertices`).
    pub(crate) fn validate(&self, handle: usize, vertices: usize) -> Result<(), InputError> {
        let bad = |what: String| Err(InputError::Keyframes { handle, what });
        if self.keyframes.is_empty() {
            return bad("no keyframes".into());
        }
        for (i, k) in self.keyframes.iter().enumerate() {
            if !k.time_s.is_finite() || !k.translation_m.iter().all(|x| x.is_finite()) {
                return bad(format!("keyframe {i} is not finite"));
            }
        }
        if let Some(i) = self.keyframes.windows(2).position(|w| w[1].time_s <= w[0].time_s) {
            return bad(format!(
                "keyframe times must increase, but keyframe {} is not after keyframe {i}",
                i + 1
            ));
        }
        if let Some(&vertex) = self.vertices.iter().find(|&&v| v >= vertices) {
            return Err(InputError::VertexOutOfRange { what: format!("handle {handle}"), vertex, vertices });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn translations_interpolate_linearly_and_hold_outside_the_keyframes() {
        let handle = Handle {
            vertices: vec![0],
            keyframes: vec![
                Keyframe { time_s: 1.0, translation_m: [0.0, 0.0, 0.0] },
                Keyframe { time_s: 3.0, translation_m: [2.0, -4.0, 0.0] },
            ],
        };
        assert_eq!(handle.translation_at(0.0), [0.0; 3]);
        assert_eq!(handle.translation_at(2.0), [1.0, -2.0, 0.0]);
        assert_eq!(handle.translation_at(3.0), [2.0, -4.0, 0.0]);
        assert_eq!(handle.translation_at(7.0), [2.0, -4.0, 0.0]);
    }
}
