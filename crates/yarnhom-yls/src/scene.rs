//! A swatch as a simulation scene: its yarns as rods of its yarn model, its glue springs and
//! the model's contact, with nothing else (no gravity, obstacles, handles or damping; a scene
//! file adds those).

use yarnhom_artifacts::Swatch;
use yarnhom_rod::rod_laws;

use crate::dynamics::{ContactModel, Scene, YarnInput};

/// The yarns, glue and contact of `swatch` as a [`Scene`]: each yarn a rod with the swatch's
/// state and rest shape, of the rod law of the swatch's yarn model
/// ([`yarnhom_rod::rod_laws`], the same reading as the periodic tile's), with mass per length
/// `ρ π r²` (the model's density, the yarn's radius); contact by the model's law.
pub fn scene_of_swatch(swatch: &Swatch) -> Scene {
    let (material, contact) = rod_laws(&swatch.model);
    let mut edge_start = 0;
    let yarns = swatch
        .yarns
        .iter()
        .map(|yarn| {
            let vertices = yarn.vertices();
            let edges = edge_start..edge_start + yarn.edge_count();
            edge_start = edges.end;
            YarnInput {
                positions_m: swatch.positions_m[vertices.clone()].to_vec(),
                edge_twist_rad: swatch.edge_twist_rad[edges.clone()].to_vec(),
                closed: yarn.closed,
                radius_m: yarn.radius_m,
                rest_length_m: swatch.rest_length_m[edges.clone()].to_vec(),
                reference_director: swatch.reference_director[edges].to_vec(),
                rest_curvature: swatch.rest_curvature[vertices.clone()].to_vec(),
                rest_twist_rad: swatch.rest_twist_rad[vertices.clone()].to_vec(),
                reference_twist_rad: swatch.reference_twist_rad[vertices].to_vec(),
                material,
                linear_density_kg_m: swatch.model.density_kg_m3
                    * std::f64::consts::PI
                    * yarn.radius_m.powi(2),
            }
        })
        .collect();
    Scene { glue: swatch.glue.clone(), contact: ContactModel::Law(contact), ..Scene::new(yarns) }
}
