//! A simulation's whole state, to continue it elsewhere to the bit: time, DOFs, velocities,
//! the rods' reference frames (moved with the rods every step) and the solver's analysed
//! sparsity pattern (the fill-reducing ordering, hence round-off, depends on it).

use nalgebra::DVector;
use serde::{Deserialize, Serialize};
use yarnhom_rod::{BendTwistReference, EdgeFrame};
use yarnhom_sparse::SpdSolver;

use super::input::InputError;
use super::simulation::Simulation;
use super::step::State;

/// The state of a [`Simulation`] ([`Simulation::checkpoint`], [`Simulation::restore`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Checkpoint {
    /// Simulated time (s).
    pub time_s: f64,
    /// All vertex positions (m), then all edge twists (rad).
    pub dofs: Vec<f64>,
    /// All vertex velocities (m/s).
    pub velocities_m_s: Vec<f64>,
    /// Per yarn, per bending-twisting element: the two edge frames' tangents and directors and
    /// the reference twist (rad).
    pub references: Vec<Vec<([[f64; 3]; 4], f64)>>,
    /// The solver's analysed pattern: matrix size and lower-triangle positions.
    pub pattern: Option<(usize, Vec<(usize, usize)>)>,
}

impl Simulation {
    /// The whole state, to continue this simulation later with [`Simulation::restore`].
    pub fn checkpoint(&self) -> Checkpoint {
        let frame = |r: &BendTwistReference| {
            let [a, b] = r.frames;
            ([a.tangent, a.director, b.tangent, b.director], r.reference_twist_rad)
        };
        Checkpoint {
            time_s: self.state.time_s,
            dofs: self.state.q.as_slice().to_vec(),
            velocities_m_s: self.state.velocity.as_slice().to_vec(),
            references: self
                .system
                .rods
                .iter()
                .map(|rod| rod.references().iter().map(frame).collect())
                .collect(),
            pattern: self.solver.analysed_pattern(),
        }
    }

    /// Continue from `checkpoint`, taken from a simulation of the same scene; then the steps
    /// are those that simulation would have taken, to the bit.
    pub fn restore(&mut self, checkpoint: &Checkpoint) -> Result<(), InputError> {
        let length = |what, got: usize, expected: usize| {
            if got == expected { Ok(()) } else { Err(InputError::Length { what, got, expected }) }
        };
        length("checkpoint DOFs", checkpoint.dofs.len(), self.state.q.len())?;
        length("checkpoint velocities", checkpoint.velocities_m_s.len(), self.state.velocity.len())?;
        length("checkpoint yarns", checkpoint.references.len(), self.system.rods.len())?;
        let finite = checkpoint.dofs.iter().chain(&checkpoint.velocities_m_s).all(|x| x.is_finite());
        if !(finite && checkpoint.time_s.is_finite()) {
            return Err(InputError::Parameter {
                what: "checkpoint state".into(),
                range: "finite",
                value: f64::NAN,
            });
        }
        let solver = match &checkpoint.pattern {
            Some((n, entries)) => {
                SpdSolver::with_pattern(*n, entries).map_err(|_| InputError::Parameter {
                    what: "checkpoint sparsity pattern".into(),
                    range: "within the matrix, lower triangle",
                    value: *n as f64,
                })?
            }
            None => SpdSolver::default(),
        };
        let frame = |&([t0, d0, t1, d1], twist): &([[f64; 3]; 4], f64)| BendTwistReference {
            frames: [EdgeFrame { tangent: t0, director: d0 }, EdgeFrame { tangent: t1, director: d1 }],
            reference_twist_rad: twist,
        };
        for (rod, saved) in self.system.rods.iter_mut().zip(&checkpoint.references) {
            let references: Vec<BendTwistReference> = saved.iter().map(frame).collect();
            rod.set_references(&references).map_err(|expected| InputError::Length {
                what: "checkpoint references",
                got: saved.len(),
                expected,
            })?;
        }
        self.state = State {
            q: DVector::from_vec(checkpoint.dofs.clone()),
            velocity: DVector::from_vec(checkpoint.velocities_m_s.clone()),
            time_s: checkpoint.time_s,
        };
        self.solver = solver;
        Ok(())
    }
}
