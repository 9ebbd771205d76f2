//! Paper 02 in a few lines: a 20 x 20 StVK membrane cloth hanging from two corners, simulated
//! with soft-constraint projection (regularized PBD and the energy-preserving alpha = beta =
//! 0.6 scheme), printing the energy every second and writing the last frame as OBJ.
//!
//! The membrane is stiff for its particles (`h^2 E / m` is large), so Gauss-Seidel needs
//! many sweeps: with 25 the unconverged projection gains energy here, with 100 (alpha = 1)
//! or 200 (alpha = 0.6, which is less forgiving of an inexact solve) it dissipates.
//!
//! Run: `cargo run --release --example cloth_hanging [OUT.obj]`

use wscg::cloth::{ClothModel, Simulation, SolverParams};
use wscg::math::TriMesh;

fn main() -> wscg::math::Result<()> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "cloth_hanging.obj".into());
    let h = 1.0 / 60.0;
    for (ab, iterations) in [(1.0, 100), (0.6, 200)] {
        let model = ClothModel::fem_grid(20, 20, (1.0, 1.0), 0.1, 500.0, 0.3)?;
        let mut sim = Simulation::new(
            model,
            SolverParams::default()
                .alpha(ab)
                .beta(ab)
                .iterations(iterations),
        )?;
        println!("alpha = beta = {ab}, {iterations} iterations");
        for second in 0..=5 {
            let e = sim.energy();
            println!(
                "  t = {second} s: kinetic {:.4} J, gravity {:.4} J, elastic {:.4} J, total {:.4} J",
                e.kinetic, e.gravity, e.elastic, e.total
            );
            sim.run(h, 60)?;
        }
        if ab == 0.6 {
            let m = sim.model();
            let faces = m.tris.iter().map(|t| t.idx.map(|i| i as u32)).collect();
            TriMesh::new(m.x.clone(), faces)?.write_obj(&out)?;
            println!("last frame written to {out}");
        }
    }
    Ok(())
}
