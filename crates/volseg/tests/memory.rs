//! Check 7: peak memory of the bone-only graph and its solver state against Grady's
//! full-image graph on the 256^3 phantom with K = 4, measured with a counting allocator
//! (this test binary's global allocator). The full-image variant runs 5 iterations only.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering::Relaxed};

use wscg_volseg::{
    fractured_shell_phantom, full_image_graph, BoneGraph, PhantomParams, RandomWalkParams,
    RandomWalkSession,
};

struct Counting;

static CURRENT: AtomicUsize = AtomicUsize::new(0);
static PEAK: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, l: Layout) -> *mut u8 {
        let p = unsafe { System.alloc(l) };
        if !p.is_null() {
            let now = CURRENT.fetch_add(l.size(), Relaxed) + l.size();
            PEAK.fetch_max(now, Relaxed);
        }
        p
    }
    unsafe fn dealloc(&self, p: *mut u8, l: Layout) {
        unsafe { System.dealloc(p, l) };
        CURRENT.fetch_sub(l.size(), Relaxed);
    }
}

#[global_allocator]
static A: Counting = Counting;

/// Peak bytes allocated by `f` above what was live when it started.
fn peak_of<R>(f: impl FnOnce() -> R) -> (R, usize) {
    let base = CURRENT.load(Relaxed);
    PEAK.store(base, Relaxed);
    let r = f();
    (r, PEAK.load(Relaxed) - base)
}

#[test]
fn bone_only_graph_needs_under_15_percent_of_the_full_image_graph() {
    let ph =
        fractured_shell_phantom(&PhantomParams::default().dims([256; 3]).fragments(4)).unwrap();
    let p = RandomWalkParams::default();
    let (bone_nodes, bone) = peak_of(|| {
        let g = BoneGraph::build(&ph.ct, &p).unwrap();
        let n = g.len();
        let mut s = RandomWalkSession::new(g, p).unwrap();
        s.set_seeds(&ph.seeds).unwrap();
        let r = s.solve(false).unwrap();
        assert!(r.converged.iter().all(|&c| c), "{r:?}");
        n
    });
    // Grady's formulation: every voxel a node, a background label seeded on the soft tissue
    // inside the shell and on the air outside it.
    let dims = ph.ct.dims();
    let mut seeds = ph.seeds.clone();
    let bg = 5u16;
    for z in 0..dims[2] {
        for y in 0..dims[1] {
            for x in 0..dims[0] {
                let c = [x, y, z];
                let centre = (0..3).all(|a| c[a].abs_diff(dims[a] / 2) <= 3);
                let corner = (0..3).all(|a| c[a] < 4);
                if centre || corner {
                    seeds.set(x, y, z, bg);
                }
            }
        }
    }
    let q = p.max_iter(5);
    let (full_nodes, full) = peak_of(|| {
        let g = full_image_graph(&ph.ct, &q).unwrap();
        let n = g.len();
        let mut s = RandomWalkSession::new(g, q).unwrap();
        s.set_seeds(&seeds).unwrap();
        let r = s.solve(false).unwrap();
        assert!(r.iterations.iter().all(|&i| i == 5), "{r:?}");
        n
    });
    let ratio = bone as f64 / full as f64;
    println!(
        "256^3 phantom, K = 4: bone-only graph {bone_nodes} nodes, peak {:.1} MB; full-image \
         graph {full_nodes} nodes (K = 5), peak {:.1} MB; ratio {ratio:.3}",
        bone as f64 / 1e6,
        full as f64 / 1e6
    );
    assert!(ratio <= 0.15, "{ratio}");
}
