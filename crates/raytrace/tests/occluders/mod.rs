//! Occlusion-heavy test scenes for paper 08's weights (hard, repeated shadow boundaries),
//! built with the public [`MeshBuilder`]: a room lit through slatted blinds and a room lit
//! through a ceiling lattice.

use wscg_raytrace::manylight::scenes::{Material, MeshBuilder, Sides};
use wscg_raytrace::manylight::{Camera, Scene};

fn camera(eye: [f64; 3], target: [f64; 3], w: usize, h: usize) -> Camera {
    Camera {
        eye,
        target,
        up: [0.0, 1.0, 0.0],
        fov_deg: 60.0,
        width: w,
        height: h,
    }
}

/// A `6 x 3 x 6` room (`x, y, z`) whose wall at `x = 0` has a window (`z` in `[2, 4]`, `y`
/// in `[1, 2.5]`) closed by ten horizontal slats (`0.1` deep, `0.015` thick, every
/// `0.15`). Outside, a closed `2 x 3 x 4` light box holds a small `0.3 x 0.3` emitter high on
/// its far wall, so that the slats cast hard stripes over the floor and the far wall.
pub fn slatted_room(w: usize, h: usize) -> (Scene, Camera) {
    let mut m = MeshBuilder::new(1).unwrap();
    let wall = Material::grey(0.7);
    m.room(
        [0.0; 3],
        [6.0, 3.0, 6.0],
        Sides {
            x_min: None,
            x_max: Some(Material::diffuse([0.65, 0.6, 0.55])),
            y_min: Some(Material::grey(0.5)),
            ..Sides::all(wall)
        },
    );
    let inward = [1.0, 0.0, 0.0];
    for (y0, y1, z0, z1) in [
        (0.0, 1.0, 0.0, 6.0),
        (2.5, 3.0, 0.0, 6.0),
        (1.0, 2.5, 0.0, 2.0),
        (1.0, 2.5, 4.0, 6.0),
    ] {
        m.quad(
            [[0.0, y0, z0], [0.0, y0, z1], [0.0, y1, z1], [0.0, y1, z0]],
            inward,
            wall,
        );
    }
    for i in 0..10 {
        let y = 1.06 + 0.15 * i as f64;
        m.boxx([-0.1, y, 2.0], [0.0, y + 0.015, 4.0], Material::grey(0.6));
    }
    m.room(
        [-2.0, 0.0, 1.0],
        [0.0, 3.0, 5.0],
        Sides {
            x_max: None,
            ..Sides::all(Material::grey(0.5))
        },
    );
    m.quad(
        [
            [-1.99, 2.55, 2.85],
            [-1.99, 2.55, 3.15],
            [-1.99, 2.85, 3.15],
            [-1.99, 2.85, 2.85],
        ],
        inward,
        Material::emitter([0.0; 3], [400.0, 380.0, 340.0]),
    );
    (
        m.build().unwrap(),
        camera([5.6, 2.4, 0.4], [1.5, 0.4, 3.5], w, h),
    )
}

/// A `6 x 3 x 6` room lit through a `2 x 2` opening in its ceiling (`x, z` in `[2, 4]`)
/// crossed by a lattice of bars (`0.04` wide, `0.08` deep, every `0.25` in both `x` and
/// `z`). Above, a closed light well of height 1.5 holds a small `0.3 x 0.3` emitter off
/// centre on its ceiling, so that the lattice casts a hard grid of shadows on the floor and
/// walls.
pub fn lattice_room(w: usize, h: usize) -> (Scene, Camera) {
    let mut m = MeshBuilder::new(1).unwrap();
    let wall = Material::grey(0.7);
    m.room(
        [0.0; 3],
        [6.0, 3.0, 6.0],
        Sides {
            y_max: None,
            y_min: Some(Material::grey(0.5)),
            z_max: Some(Material::diffuse([0.55, 0.6, 0.65])),
            ..Sides::all(wall)
        },
    );
    let down = [0.0, -1.0, 0.0];
    for (x0, x1, z0, z1) in [
        (0.0, 2.0, 0.0, 6.0),
        (4.0, 6.0, 0.0, 6.0),
        (2.0, 4.0, 0.0, 2.0),
        (2.0, 4.0, 4.0, 6.0),
    ] {
        m.quad(
            [[x0, 3.0, z0], [x1, 3.0, z0], [x1, 3.0, z1], [x0, 3.0, z1]],
            down,
            wall,
        );
    }
    let bar = Material::grey(0.6);
    for i in 1..8 {
        let c = 2.0 + 0.25 * i as f64;
        m.boxx([c - 0.02, 2.92, 2.0], [c + 0.02, 3.0, 4.0], bar);
        m.boxx([2.0, 2.92, c - 0.02], [4.0, 2.92 + 0.04, c + 0.02], bar);
    }
    m.room(
        [2.0, 3.0, 2.0],
        [4.0, 4.5, 4.0],
        Sides {
            y_min: None,
            ..Sides::all(Material::grey(0.5))
        },
    );
    m.quad(
        [
            [2.35, 4.49, 2.45],
            [2.65, 4.49, 2.45],
            [2.65, 4.49, 2.75],
            [2.35, 4.49, 2.75],
        ],
        down,
        Material::emitter([0.0; 3], [400.0, 380.0, 340.0]),
    );
    (
        m.build().unwrap(),
        camera([0.4, 2.2, 0.4], [4.0, 0.3, 4.5], w, h),
    )
}
