//! `wscg cloth simulate`: paper 02 on the user's own garment mesh.
//!
//! Reads an OBJ or PLY triangle mesh, pins the listed vertices (or the highest ones), runs
//! the chosen integrator (with optional obstacles: a floor, spheres, capsules, closed meshes,
//! and self contacts) and writes one OBJ per output frame (`frame_0000.obj`, ...) plus an
//! `energy.csv` with the kinetic, gravitational, elastic and total energy of every frame.

use std::path::PathBuf;

use clap::{Args, Subcommand, ValueEnum};
use wscg_cloth::{
    ClothModel, Collider, Collisions, LambdaMode, MeshCollider, Method, NcgVariant, Relaxation,
    Simulation, SolverParams,
};
use wscg_math::progress::Progress;
use wscg_math::{Error, Result, TriMesh};

use crate::progress::Bars;

#[derive(Subcommand, Debug)]
pub enum ClothCommand {
    /// Simulate a triangle mesh (OBJ/PLY) hanging from pinned vertices.
    Simulate(SimulateArgs),
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum MethodName {
    /// Soft-constraint projection with the alpha/beta scheme (the paper).
    Soft,
    /// The paper's nonlinear conjugate gradient implicit solver.
    Ncg,
    /// Plain position-based dynamics (baseline).
    Pbd,
    /// One linearised implicit Euler step by conjugate gradients (baseline).
    IeCg,
    /// One linearised implicit Euler step by sparse Cholesky (baseline).
    IeDirect,
    /// Exact implicit Euler by Newton's method (reference).
    IeNewton,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum RelaxationName {
    /// Sequential Gauss-Seidel.
    Gs,
    /// Graph-coloured Gauss-Seidel, colour classes in parallel.
    Colored,
    /// Jacobi with relaxation --omega.
    Jacobi,
    /// Successive over-relaxation with --omega.
    Sor,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Material {
    /// StVK membrane triangles (Young's modulus --young, Poisson ratio --poisson).
    Fem,
    /// Edge links (--k-edge) and bending links across interior edges (--k-bend).
    Links,
}

#[derive(Args, Debug)]
pub struct SimulateArgs {
    /// Input mesh (.obj or .ply); it is only read.
    #[arg(long)]
    mesh: PathBuf,
    /// Output folder for frame_NNNN.obj and energy.csv.
    #[arg(long)]
    out: PathBuf,
    /// Vertex indices to pin (comma separated); default: the vertices within 1 mm of the
    /// highest y.
    #[arg(long, value_delimiter = ',')]
    pin: Vec<usize>,
    /// Number of output frames.
    #[arg(long, default_value_t = 300)]
    frames: usize,
    /// Time step (s); one step per frame.
    #[arg(long, default_value_t = 1.0 / 60.0)]
    h: f64,
    /// Total cloth mass (kg).
    #[arg(long, default_value_t = 0.1)]
    mass: f64,
    /// Material model.
    #[arg(long, value_enum, default_value_t = Material::Fem)]
    material: Material,
    /// Young's modulus of the membrane (N/m).
    #[arg(long, default_value_t = 1000.0)]
    young: f64,
    /// Poisson ratio.
    #[arg(long, default_value_t = 0.3)]
    poisson: f64,
    /// Edge-link stiffness (N/m).
    #[arg(long, default_value_t = 2000.0)]
    k_edge: f64,
    /// Bending-link stiffness (N/m).
    #[arg(long)]
    k_bend: Option<f64>,
    /// Integrator.
    #[arg(long, value_enum, default_value_t = MethodName::Soft)]
    method: MethodName,
    /// Iterations per step.
    #[arg(long, default_value_t = 25)]
    iterations: usize,
    /// alpha = beta of the soft projection, in [0.5, 1] (1: implicit Euler).
    #[arg(long, default_value_t = 1.0)]
    alpha_beta: f64,
    /// Constraint damping gamma (s).
    #[arg(long, default_value_t = 0.0)]
    gamma: f64,
    /// Use the paper's printed multiplier reset instead of accumulation.
    #[arg(long)]
    paper_reset: bool,
    /// Constraint sweep of the soft projection.
    #[arg(long, value_enum, default_value_t = RelaxationName::Gs)]
    relaxation: RelaxationName,
    /// Relaxation factor of Jacobi (default 0.15) or SOR (default 1.5).
    #[arg(long)]
    omega: Option<f64>,
    /// A floor: the plane y = FLOOR.
    #[arg(long, allow_hyphen_values = true)]
    floor: Option<f64>,
    /// A sphere obstacle `cx,cy,cz,r` (repeatable).
    #[arg(long, allow_hyphen_values = true)]
    sphere: Vec<String>,
    /// A capsule obstacle `ax,ay,az,bx,by,bz,r` (repeatable).
    #[arg(long, allow_hyphen_values = true)]
    capsule: Vec<String>,
    /// A closed triangle mesh obstacle (.obj or .ply, outward normals; repeatable).
    #[arg(long)]
    collider: Vec<PathBuf>,
    /// Cloth thickness kept from obstacles and between layers (m).
    #[arg(long, default_value_t = 0.005)]
    thickness: f64,
    /// Coulomb friction coefficient against obstacles.
    #[arg(long, default_value_t = 0.3)]
    friction: f64,
    /// Keep particles that share no constraint `thickness` apart.
    #[arg(long)]
    self_collision: bool,
}

/// The obstacles named on the command line.
fn colliders(a: &SimulateArgs) -> Result<Vec<Collider>> {
    let mut out = Vec::new();
    if let Some(y) = a.floor {
        out.push(Collider::plane([0.0, 1.0, 0.0], [0.0, y, 0.0])?);
    }
    for s in &a.sphere {
        let s = numbers("sphere", s, 4)?;
        out.push(Collider::Sphere {
            center: [s[0], s[1], s[2]],
            radius: s[3],
        });
    }
    for c in &a.capsule {
        let c = numbers("capsule", c, 7)?;
        out.push(Collider::Capsule {
            a: [c[0], c[1], c[2]],
            b: [c[3], c[4], c[5]],
            radius: c[6],
        });
    }
    for path in &a.collider {
        let (v, f) = read_mesh(path)?;
        out.push(Collider::Mesh(MeshCollider::new(&v, &f)?));
    }
    Ok(out)
}

/// `n` comma-separated numbers of option `name`.
fn numbers(name: &'static str, text: &str, n: usize) -> Result<Vec<f64>> {
    let v: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| Error::invalid(name, format!("{text:?}: {e}")))?;
    if v.len() != n {
        return Err(Error::invalid(
            name,
            format!("{text:?}: expected {n} comma-separated numbers"),
        ));
    }
    Ok(v)
}

/// Vertices and triangles of a mesh.
type MeshData = (Vec<[f64; 3]>, Vec<[usize; 3]>);

/// Vertices and triangles of an OBJ/PLY file.
fn read_mesh(path: &std::path::Path) -> Result<MeshData> {
    let mesh = TriMesh::read(path)?;
    let f = mesh.faces.iter().map(|f| f.map(|i| i as usize)).collect();
    Ok((mesh.positions, f))
}

/// Runs a `wscg cloth` command.
pub fn run(cmd: ClothCommand) -> Result<()> {
    let ClothCommand::Simulate(a) = cmd;
    crate::commands::overwrite::check_folder(
        "out",
        &a.out,
        [&a.mesh].into_iter().chain(&a.collider),
    )?;
    let mesh = TriMesh::read(&a.mesh)?;
    let (v, faces) = read_mesh(&a.mesh)?;
    let material = match a.material {
        Material::Fem => Some((a.young, a.poisson)),
        Material::Links => None,
    };
    let mut model = ClothModel::from_trimesh(&v, &faces, a.mass, material, a.k_edge, a.k_bend)?;
    let pins = if a.pin.is_empty() {
        let top = v.iter().map(|p| p[1]).fold(f64::MIN, f64::max);
        (0..v.len()).filter(|&i| v[i][1] >= top - 1e-3).collect()
    } else {
        a.pin.clone()
    };
    if let Some(&p) = pins.iter().find(|&&p| p >= v.len()) {
        return Err(Error::invalid(
            "pin",
            format!("vertex {p} out of range for {} vertices", v.len()),
        ));
    }
    for &p in &pins {
        model.inv_mass[p] = 0.0;
    }
    let method = match a.method {
        MethodName::Soft => Method::SoftProjection,
        MethodName::Ncg => Method::Ncg {
            variant: NcgVariant::Consistent,
        },
        MethodName::Pbd => Method::PlainPbd { stiffness: 1.0 },
        MethodName::IeCg => Method::ImplicitEulerCg {
            tol: 1e-8,
            max_iter: 1000,
        },
        MethodName::IeDirect => Method::ImplicitEulerDirect,
        MethodName::IeNewton => Method::ImplicitEulerNewton { tol: 1e-10 },
    };
    let mut sim = Simulation::new(
        model,
        SolverParams::default()
            .method(method)
            .iterations(a.iterations)
            .alpha(a.alpha_beta)
            .beta(a.alpha_beta)
            .gamma(a.gamma)
            .lambda_mode(if a.paper_reset {
                LambdaMode::PaperReset
            } else {
                LambdaMode::Accumulate
            })
            .velocity_damping(0.0)
            .relaxation(match a.relaxation {
                RelaxationName::Gs => Relaxation::GaussSeidel,
                RelaxationName::Colored => Relaxation::ColoredGaussSeidel,
                RelaxationName::Jacobi => Relaxation::Jacobi {
                    omega: a.omega.unwrap_or(0.15),
                },
                RelaxationName::Sor => Relaxation::Sor {
                    omega: a.omega.unwrap_or(1.5),
                },
            }),
    )?;
    sim.set_collisions(Collisions {
        colliders: colliders(&a)?,
        thickness: a.thickness,
        friction: a.friction,
        self_collision: a.self_collision,
    })?;
    std::fs::create_dir_all(&a.out).map_err(|e| Error::io(&a.out, e))?;
    let csv_path = a.out.join("energy.csv");
    let mut lines = String::from("frame,time,kinetic,gravity,elastic,total\n");
    let bars = Bars::new("cloth");
    bars.begin("simulating", a.frames as u64);
    let mut frame_mesh = mesh.clone();
    for f in 0..a.frames {
        if f > 0 {
            sim.step(a.h)?;
        }
        let e = sim.energy();
        lines.push_str(&format!(
            "{f},{},{},{},{},{}\n",
            f as f64 * a.h,
            e.kinetic,
            e.gravity,
            e.elastic,
            e.total
        ));
        frame_mesh.positions.clone_from(&sim.model().x);
        frame_mesh.normals = None;
        frame_mesh.write_obj(a.out.join(format!("frame_{f:04}.obj")))?;
        bars.advance(1);
    }
    bars.finish();
    wscg_math::io::atomic::write(&csv_path, lines)?;
    println!(
        "{} frames of {} vertices ({} pinned) written to {}",
        a.frames,
        v.len(),
        pins.len(),
        a.out.display()
    );
    Ok(())
}
