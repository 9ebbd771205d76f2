//! Online synthesis of the walk-and-reach sequence (paper §2.2 and §2.4–2.5, Fig. 3).
//!
//! A star network of Hopf oscillators runs at the current action's frequency `ω_a = 2π/T_a`;
//! each periodic source is read from its follower through the learned state map, with delays
//! applied as rotations of the follower state; weights and means come from LWLR of the action's
//! step parameters and are blended across action boundaries; the planner is re-run from the
//! remaining distance just before every boundary (when the blend window opens), so a goal that
//! moves inserts or removes steps on the fly.

use crate::blend::{
    blend_alpha, blend_linear, blend_nonperiodic, check_beta, nonperiodic_source, signed_phase,
    DEFAULT_BETA,
};
use crate::hopf::{rotate, StarNetwork};
use crate::lwlr::{Lwlr, DEFAULT_RIDGE};
use crate::map::{DelayedLuts, FourierMap, StateMap, SvrMap, SvrMapParams, MAX_LUT_SIZE};
use crate::planner::{Action, PlannedAction, Planner};
use crate::stepwise::ActionLibrary;
use std::f64::consts::TAU;
use wscg_math::{Error, Result};

/// Which state maps drive the sources.
#[derive(Clone, Debug, PartialEq)]
pub enum MapKind {
    /// The learned Fourier series at the follower's angle (exact on the attractor).
    Fourier,
    /// A phase table of the given size, linearly interpolated (the fast path).
    Lut(usize),
    /// ε-SVR maps from the follower state, as in the paper.
    Svr(SvrMapParams),
}

wscg_math::params! {
    /// Parameters of the synthesizer.
    #[derive(Clone, Debug, PartialEq)]
    pub struct SynthesizerParams {
        /// Blend half-width `β` (radians), `π/5` in the paper.
        pub beta: f64,
        /// Coupling `k` of the followers (not given in the paper; > 1 guarantees contraction).
        pub coupling: f64,
        /// State maps.
        pub map: MapKind,
        /// LWLR bandwidth of the weight regression (`None`: leave-one-out selection).
        pub bandwidth: Option<f64>,
    }
}

impl Default for SynthesizerParams {
    fn default() -> Self {
        Self {
            beta: DEFAULT_BETA,
            coupling: 2.0,
            map: MapKind::Lut(1024),
            bandwidth: None,
        }
    }
}

impl SynthesizerParams {
    /// Errors: `beta` outside `(0, π)`, a negative or non-finite `coupling`, a phase table
    /// size outside `4..=`[`MAX_LUT_SIZE`], invalid SVR map parameters, a non-positive or NaN
    /// `bandwidth` (`+inf` is global linear least squares).
    pub fn validate(&self) -> Result<()> {
        check_beta(self.beta)?;
        if !(self.coupling.is_finite() && self.coupling >= 0.0) {
            return Err(Error::invalid(
                "coupling",
                format!("must be finite and >= 0, got {}", self.coupling),
            ));
        }
        match &self.map {
            MapKind::Lut(size) if !(4..=MAX_LUT_SIZE).contains(size) => {
                return Err(Error::invalid(
                    "map",
                    format!("the phase table size must be in 4..={MAX_LUT_SIZE}, got {size}"),
                ));
            }
            MapKind::Svr(c) => c.validate()?,
            MapKind::Lut(_) | MapKind::Fourier => {}
        }
        if let Some(h) = self.bandwidth {
            if h.is_nan() || h <= 0.0 {
                return Err(Error::invalid("bandwidth", format!("must be > 0, got {h}")));
            }
        }
        Ok(())
    }
}

/// Means and weights of one action instance: `[means (I), w0 (I), weights (I × J)]`.
#[derive(Clone, Debug, PartialEq)]
pub struct ActionWeights {
    /// Means `m_i`.
    pub means: Vec<f64>,
    /// Non-periodic weights `W_i0`.
    pub w0: Vec<f64>,
    /// Periodic weights `W_ij`, `I × J`.
    pub weights: Vec<f64>,
}

impl ActionWeights {
    /// Splits a regression output vector.
    pub fn from_vector(v: &[f64], n_channels: usize) -> Self {
        Self {
            means: v[..n_channels].to_vec(),
            w0: v[n_channels..2 * n_channels].to_vec(),
            weights: v[2 * n_channels..].to_vec(),
        }
    }

    /// These means and `w0` with source-major periodic weights `by_source`.
    fn mix_view<'a>(&'a self, by_source: &'a [f64]) -> MixWeights<'a> {
        MixWeights {
            means: &self.means,
            w0: &self.w0,
            by_source,
        }
    }
}

/// The weight and duration regressions of one action.
#[derive(Clone, Debug)]
pub struct ActionRegression {
    /// `(step parameter, duration) → [means, w0, weights]`.
    pub weights: Lwlr,
    /// `step parameter → duration`.
    pub duration: Lwlr,
}

/// Fits the LWLR models of the three actions from the library's per-trial fits.
///
/// # Errors
/// Fewer trials than the regression needs, or an invalid bandwidth.
pub fn fit_regressions(
    lib: &ActionLibrary,
    bandwidth: Option<f64>,
) -> Result<Vec<ActionRegression>> {
    (0..3)
        .map(|a| {
            let params = &lib.params[a];
            let x: Vec<Vec<f64>> = params.iter().map(|&(p, t)| vec![p, t]).collect();
            let y: Vec<Vec<f64>> = (0..params.len()).map(|r| lib.weight_vector(a, r)).collect();
            let px: Vec<Vec<f64>> = params.iter().map(|&(p, _)| vec![p]).collect();
            let py: Vec<Vec<f64>> = params.iter().map(|&(_, t)| vec![t]).collect();
            Ok(ActionRegression {
                weights: Lwlr::fit(&x, &y, bandwidth, DEFAULT_RIDGE)?,
                duration: Lwlr::fit(&px, &py, bandwidth, DEFAULT_RIDGE)?,
            })
        })
        .collect()
}

/// `J × I` (source-major) copy of an `I × J` matrix.
fn source_major(m: &[f64], i_n: usize) -> Vec<f64> {
    let j_n = m.len().checked_div(i_n).unwrap_or(0);
    let mut t = vec![0.0; m.len()];
    for (i, row) in m.chunks_exact(j_n.max(1)).enumerate() {
        for (j, &v) in row.iter().enumerate() {
            t[j * i_n + i] = v;
        }
    }
    t
}

/// An action's weights with the periodic ones source-major (`J × I`), the layout in which
/// the mixing is a few contiguous multiply-adds per source.
#[derive(Clone, Copy)]
struct MixWeights<'a> {
    means: &'a [f64],
    w0: &'a [f64],
    by_source: &'a [f64],
}

/// [`mix_frame`] with source-major weights and sources (`J × I`).
fn mix_source_major(
    prev: Option<MixWeights>,
    cur: MixWeights,
    next: Option<MixWeights>,
    psi: f64,
    beta: f64,
    sources: &[f64],
    out: &mut [f64],
) {
    let phi = signed_phase(psi);
    let (a, b) = if phi < 0.0 {
        (Some(cur), next)
    } else {
        (prev, Some(cur))
    };
    let s0 = nonperiodic_source(psi);
    let i_n = out.len().max(1);
    let rows = sources.chunks_exact(i_n);
    match (a, b) {
        (Some(p), Some(q)) => {
            let alpha = blend_alpha(phi, beta);
            let constant = out.iter_mut().zip(p.means.iter().zip(q.means));
            for ((o, (&mp, &mq)), (&wp, &wq)) in constant.zip(p.w0.iter().zip(q.w0)) {
                *o = blend_linear(mp, mq, alpha) + blend_nonperiodic(wp, wq, alpha, phi) * s0;
            }
            let per_source = rows.zip(
                p.by_source
                    .chunks_exact(i_n)
                    .zip(q.by_source.chunks_exact(i_n)),
            );
            for (s, (wp, wq)) in per_source {
                for (((o, &x), &y), &sj) in out.iter_mut().zip(wp).zip(wq).zip(s) {
                    *o += blend_linear(x, y, alpha) * sj;
                }
            }
        }
        (Some(w), None) | (None, Some(w)) => {
            for ((o, &m), &w0) in out.iter_mut().zip(w.means).zip(w.w0) {
                *o = m + w0 * s0;
            }
            for (s, wr) in rows.zip(w.by_source.chunks_exact(i_n)) {
                for ((o, &x), &sj) in out.iter_mut().zip(wr).zip(s) {
                    *o += x * sj;
                }
            }
        }
        (None, None) => out.iter_mut().for_each(|o| *o = 0.0),
    }
}

/// The posture `ξ_i = m_i + W_i0 s₀ + Σ_j W_ij s_ij` at raw leader phase `ψ`, blending `prev`
/// into `cur` after the boundary and `cur` into `next` before the next one (paper §2.4).
/// `sources` holds the (delayed) source values `s_ij`, `I × J`.
pub fn mix_frame(
    prev: Option<&ActionWeights>,
    cur: &ActionWeights,
    next: Option<&ActionWeights>,
    psi: f64,
    beta: f64,
    sources: &[f64],
    out: &mut [f64],
) {
    let i_n = out.len();
    let t = |w: Option<&ActionWeights>| w.map(|w| source_major(&w.weights, i_n));
    let (tp, tc, tn) = (t(prev), source_major(&cur.weights, i_n), t(next));
    mix_source_major(
        prev.zip(tp.as_deref()).map(|(w, by)| w.mix_view(by)),
        cur.mix_view(&tc),
        next.zip(tn.as_deref()).map(|(w, by)| w.mix_view(by)),
        psi,
        beta,
        &source_major(sources, i_n),
        out,
    );
}

/// One synthesized frame.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    /// Time since the start (seconds).
    pub time: f64,
    /// Joint angles (the library's channels).
    pub angles: Vec<f64>,
    /// Pelvis forward position (metres from the start).
    pub root_x: f64,
    /// The current action.
    pub action: Action,
    /// Leader phase `ψ ∈ [0, 2π)`.
    pub phase: f64,
}

/// An action being executed.
#[derive(Clone, Debug)]
struct Active {
    planned: PlannedAction,
    duration: f64,
    weights: ActionWeights,
    /// `weights.weights` source-major (`J × I`).
    by_source: Vec<f64>,
    start_x: f64,
}

impl Active {
    fn mix_view(&self) -> MixWeights<'_> {
        self.weights.mix_view(&self.by_source)
    }
}

/// The result of [`Synthesizer::run`].
#[derive(Clone, Debug, Default)]
pub struct Synthesis {
    /// Frames at the requested rate, the last one at the end of the reach.
    pub frames: Vec<Frame>,
    /// The executed actions in order.
    pub executed: Vec<PlannedAction>,
    /// Postures exactly at each action boundary (`ψ = 0` of the next action).
    pub transitions: Vec<Vec<f64>>,
    /// The initial goal was closer than the comfort distance plus the smallest step: only the
    /// reach is performed.
    pub too_short: bool,
}

impl Synthesis {
    /// Time (seconds) at which the reach starts: the duration of the approach.
    pub fn approach_time(&self) -> Option<f64> {
        self.frames
            .iter()
            .find(|f| f.action == Action::Reach)
            .map(|f| f.time)
    }

    /// Number of walking steps executed.
    pub fn n_steps(&self) -> usize {
        self.executed
            .iter()
            .filter(|a| a.action != Action::Reach)
            .count()
    }

    /// The frames as a BVH motion (pelvis walking along +z).
    pub fn bvh_motion(&self, frame_time: f64) -> crate::bvh::BvhMotion {
        let angles = self.frames.iter().map(|f| f.angles.clone()).collect();
        let roots: Vec<f64> = self.frames.iter().map(|f| f.root_x).collect();
        crate::bvh::motion_from_frames(angles, &roots, frame_time)
    }

    /// Final pelvis-to-goal distance for a goal at `goal` metres.
    pub fn final_distance(&self, goal: f64) -> Option<f64> {
        self.frames.last().map(|f| goal - f.root_x)
    }
}

/// The online synthesizer.
pub struct Synthesizer {
    lib: ActionLibrary,
    regs: Vec<ActionRegression>,
    /// State maps of the Fourier and SVR kinds (empty on the LUT path).
    maps: Vec<Box<dyn StateMap>>,
    angle_only: bool,
    /// Delayed phase tables of the LUT path, read without dynamic dispatch.
    luts: Option<DelayedLuts>,
    /// `2π τ_ij`, `I × J`.
    rot: Vec<f64>,
    planner: Planner,
    cfg: SynthesizerParams,
    net: StarNetwork,
    /// The leader phase `ψ` of `net`, kept in step with it.
    psi: f64,
    goal: f64,
    prev: Option<Active>,
    cur: Active,
    next: Option<Active>,
    time: f64,
    finished: bool,
    too_short: bool,
    executed: Vec<PlannedAction>,
    transitions: Vec<Vec<f64>>,
    src: Vec<f64>,
}

/// A planner with the step ranges the library was trained on.
pub fn planner_for(lib: &ActionLibrary) -> Planner {
    let range = |a: usize| {
        let v = lib.params[a].iter().map(|p| p.0);
        (
            v.clone().fold(f64::INFINITY, f64::min),
            v.fold(f64::NEG_INFINITY, f64::max),
        )
    };
    Planner {
        range1: range(0),
        range2: range(1),
        ..Planner::default()
    }
}

impl Synthesizer {
    /// Builds the regressions and state maps; call [`Synthesizer::reset`] before stepping (or
    /// use [`Synthesizer::run`]).
    ///
    /// # Errors
    /// Invalid parameters (see [`SynthesizerParams::validate`]), an invalid planner, or a
    /// regression or map that cannot be fitted.
    pub fn new(lib: ActionLibrary, planner: Planner, cfg: SynthesizerParams) -> Result<Self> {
        cfg.validate()?;
        planner.validate()?;
        let regs = fit_regressions(&lib, cfg.bandwidth)?;
        // The LUT path reads its delayed tables directly; the other kinds go through the maps.
        let luts = match &cfg.map {
            MapKind::Lut(size) => Some(DelayedLuts::new(&lib.sources, &lib.delays, *size)?),
            _ => None,
        };
        let maps: Vec<Box<dyn StateMap>> = lib
            .sources
            .iter()
            .filter_map(|s| -> Option<Result<Box<dyn StateMap>>> {
                match &cfg.map {
                    MapKind::Lut(_) => None,
                    MapKind::Fourier => Some(Ok(Box::new(FourierMap { source: s.clone() }))),
                    MapKind::Svr(c) => Some(SvrMap::fit(s, c).map(|m| Box::new(m) as _)),
                }
            })
            .collect::<Result<_>>()?;
        let angle_only = maps.iter().all(|m| m.angle_only());
        let rot = lib.delays.iter().map(|t| TAU * t).collect();
        let j_n = lib.n_sources();
        let net = StarNetwork::new(TAU, cfg.coupling, j_n)?;
        let placeholder = Active {
            planned: PlannedAction {
                action: Action::Reach,
                length: 0.0,
            },
            duration: 1.0,
            weights: ActionWeights {
                means: vec![],
                w0: vec![],
                weights: vec![],
            },
            by_source: vec![],
            start_x: 0.0,
        };
        let src = vec![0.0; lib.n_channels * j_n];
        Ok(Self {
            lib,
            regs,
            maps,
            angle_only,
            luts,
            rot,
            planner,
            cfg,
            net,
            psi: 0.0,
            goal: 0.0,
            prev: None,
            cur: placeholder,
            next: None,
            time: 0.0,
            finished: true,
            too_short: false,
            executed: Vec::new(),
            transitions: Vec::new(),
            src,
        })
    }

    /// A synthesizer with the paper's defaults, the given state maps and a planner whose step
    /// ranges are the library's training ranges.
    ///
    /// # Errors
    /// As [`Synthesizer::new`].
    pub fn from_library(lib: ActionLibrary, map: MapKind) -> Result<Self> {
        let planner = planner_for(&lib);
        Self::new(
            lib,
            planner,
            SynthesizerParams {
                map,
                ..SynthesizerParams::default()
            },
        )
    }

    /// Runs `goal` unchanged and then with the goal moved to `new_goal` at the fraction `at` of
    /// the unchanged approach (paper Fig. 10). Returns both sequences.
    ///
    /// # Errors
    /// As [`Synthesizer::run`].
    pub fn run_goal_jump(
        &mut self,
        goal: f64,
        new_goal: f64,
        at: f64,
        fps: f64,
        max_seconds: f64,
    ) -> Result<(Synthesis, Synthesis)> {
        let base = self.run(goal, fps, &[], max_seconds)?;
        let t = at * base.approach_time().unwrap_or(0.0);
        let jump = self.run(goal, fps, &[(t, new_goal)], max_seconds)?;
        Ok((base, jump))
    }

    /// The learned library.
    pub fn library(&self) -> &ActionLibrary {
        &self.lib
    }

    /// The weight and duration regressions.
    pub fn regressions(&self) -> &[ActionRegression] {
        &self.regs
    }

    /// The planner.
    pub fn planner(&self) -> &Planner {
        &self.planner
    }

    fn activate(&self, planned: PlannedAction, prev_length: f64, start_x: f64) -> Result<Active> {
        let a = planned.action.index();
        let p = if planned.action == Action::Reach {
            prev_length
        } else {
            planned.length
        };
        let duration = self.regs[a].duration.predict(&[p])?[0];
        if !(duration.is_finite() && duration > 0.0) {
            return Err(Error::Numerical(format!(
                "predicted a non-positive duration {duration} s"
            )));
        }
        let y = self.regs[a].weights.predict(&[p, duration])?;
        let weights = ActionWeights::from_vector(&y, self.lib.n_channels);
        Ok(Active {
            planned,
            duration,
            by_source: source_major(&weights.weights, self.lib.n_channels),
            weights,
            start_x,
        })
    }

    fn mean_reach_param(&self) -> f64 {
        let p = &self.lib.params[2];
        p.iter().map(|v| v.0).sum::<f64>() / p.len().max(1) as f64
    }

    /// Starts a new sequence towards a goal at distance `goal` (metres, pelvis to drawer).
    ///
    /// # Errors
    /// `goal` not finite or ≤ 0.
    pub fn reset(&mut self, goal: f64) -> Result<()> {
        let plan = self.planner.plan(goal)?;
        self.goal = goal;
        self.too_short = plan.too_short;
        let first = if plan.too_short {
            PlannedAction {
                action: Action::Reach,
                length: 0.0,
            }
        } else {
            plan.actions[0]
        };
        let reach_p = self.mean_reach_param();
        self.cur = self.activate(first, reach_p, 0.0)?;
        self.prev = None;
        self.next = None;
        self.time = 0.0;
        self.finished = false;
        self.executed = vec![first];
        self.transitions.clear();
        let j_n = self.lib.n_sources();
        self.net = StarNetwork::new(TAU / self.cur.duration, self.cfg.coupling, j_n)?;
        self.psi = self.net.phase();
        Ok(())
    }

    /// Moves the goal (takes effect at the next re-planning, when the next blend window opens).
    ///
    /// # Errors
    /// `goal` not finite or ≤ 0.
    pub fn set_goal(&mut self, goal: f64) -> Result<()> {
        if !(goal.is_finite() && goal > 0.0) {
            return Err(Error::invalid(
                "goal",
                format!("distance must be finite and > 0, got {goal}"),
            ));
        }
        self.goal = goal;
        Ok(())
    }

    /// Whether the reach has completed.
    pub fn finished(&self) -> bool {
        self.finished
    }

    /// Chooses the action after the current one from the remaining distance.
    fn decide_next(&mut self) -> Result<()> {
        if self.cur.planned.action == Action::Reach {
            return Ok(());
        }
        let end_x = self.cur.start_x + self.cur.planned.length;
        let remaining = self.goal - end_x;
        let reach = PlannedAction {
            action: Action::Reach,
            length: 0.0,
        };
        let planned = if remaining > 0.0 {
            let plan = self.planner.plan(remaining)?;
            if plan.too_short {
                reach
            } else {
                plan.actions[0]
            }
        } else {
            reach
        };
        self.next = Some(self.activate(planned, self.cur.planned.length, end_x)?);
        Ok(())
    }

    /// Crosses an action boundary (leader phase 2π → 0).
    fn boundary(&mut self) -> Result<()> {
        if self.cur.planned.action == Action::Reach {
            self.finished = true;
            return Ok(());
        }
        if self.next.is_none() {
            self.decide_next()?;
        }
        let next = self
            .next
            .take()
            .ok_or_else(|| Error::Numerical("no next action at a boundary".into()))?;
        let old = std::mem::replace(&mut self.cur, next);
        self.prev = Some(old);
        self.executed.push(self.cur.planned);
        self.net.set_omega(TAU / self.cur.duration)?;
        // Snap the tiny integration overshoot so that the new action starts at ψ = 0 exactly.
        let psi = self.net.phase();
        let d = if psi > std::f64::consts::PI {
            psi - TAU
        } else {
            psi
        };
        self.net.leader = rotate(self.net.leader, -d);
        for f in &mut self.net.followers {
            *f = rotate(*f, -d);
        }
        let mut post = vec![0.0; self.lib.n_channels];
        self.posture(0.0, &mut post);
        self.transitions.push(post);
        Ok(())
    }

    /// Advances the oscillators by `dt`, crossing boundaries exactly at `ψ = 0`.
    ///
    /// # Errors
    /// `dt` not finite and > 0, or a failed regression prediction.
    pub fn step(&mut self, dt: f64) -> Result<()> {
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::invalid(
                "dt",
                format!("must be finite and > 0, got {dt}"),
            ));
        }
        let window = TAU - self.cfg.beta;
        let mut remaining = dt;
        while remaining > 1e-15 && !self.finished {
            let to_wrap = (TAU - self.psi) / self.net.omega;
            if remaining < to_wrap {
                self.net.step_rk4(remaining)?;
                self.time += remaining;
                remaining = 0.0;
            } else {
                if to_wrap > 0.0 {
                    self.net.step_rk4(to_wrap)?;
                }
                self.time += to_wrap;
                remaining -= to_wrap;
                self.boundary()?;
            }
            self.psi = self.net.phase();
            if self.next.is_none() && !self.finished && self.psi >= window {
                self.decide_next()?;
            }
        }
        Ok(())
    }

    fn source_values(&mut self) {
        let j_n = self.lib.n_sources();
        if let Some(luts) = &self.luts {
            let mut th = [0.0f64; 16];
            if j_n <= th.len() {
                for (t, f) in th.iter_mut().zip(&self.net.followers) {
                    *t = crate::hopf::phase(*f);
                }
                luts.eval(&th[..j_n], &mut self.src);
            } else {
                let th: Vec<f64> = self
                    .net
                    .followers
                    .iter()
                    .map(|f| crate::hopf::phase(*f))
                    .collect();
                luts.eval(&th, &mut self.src);
            }
        } else {
            // Source-major `J × I`; `rot` is `I × J`.
            let i_n = self.lib.n_channels;
            for (j, (row, map)) in self
                .src
                .chunks_exact_mut(i_n.max(1))
                .zip(&self.maps)
                .enumerate()
            {
                let f = self.net.followers[j];
                let th = crate::hopf::phase(f);
                for (i, v) in row.iter_mut().enumerate() {
                    let rot = self.rot[i * j_n + j];
                    *v = if self.angle_only {
                        map.eval_angle(th - rot)
                    } else {
                        map.eval(rotate(f, -rot))
                    };
                }
            }
        }
    }

    fn posture(&mut self, psi: f64, out: &mut [f64]) {
        self.source_values();
        mix_source_major(
            self.prev.as_ref().map(Active::mix_view),
            self.cur.mix_view(),
            self.next.as_ref().map(Active::mix_view),
            psi,
            self.cfg.beta,
            &self.src,
            out,
        );
    }

    /// The frame at the current state.
    pub fn frame(&mut self) -> Frame {
        let mut frame = Frame {
            time: 0.0,
            angles: Vec::new(),
            root_x: 0.0,
            action: Action::Reach,
            phase: 0.0,
        };
        self.frame_into(&mut frame);
        frame
    }

    /// Writes the frame at the current state into `frame`, reusing its angle buffer: the
    /// allocation-free form of [`Synthesizer::frame`] for a real-time loop.
    pub fn frame_into(&mut self, frame: &mut Frame) {
        // After the reach the phase has wrapped to 0: report the end of the action instead.
        let psi = if self.finished {
            TAU * (1.0 - 1e-12)
        } else {
            self.psi
        };
        frame.angles.resize(self.lib.n_channels, 0.0);
        self.posture(psi, &mut frame.angles);
        frame.root_x = self.cur.start_x + self.cur.planned.length * self.lib.progress_at(psi / TAU);
        frame.time = self.time;
        frame.action = self.cur.planned.action;
        frame.phase = psi;
    }

    /// Synthesizes a whole sequence at `fps` towards `goal`, applying `(time, goal)` changes when
    /// their time is reached.
    ///
    /// # Errors
    /// `fps` not finite and > 0, a goal not finite and > 0 (initial or changed), or more than
    /// `max_seconds` of motion (a goal that keeps receding).
    pub fn run(
        &mut self,
        goal: f64,
        fps: f64,
        goal_changes: &[(f64, f64)],
        max_seconds: f64,
    ) -> Result<Synthesis> {
        if !(fps.is_finite() && fps > 0.0) {
            return Err(Error::invalid(
                "fps",
                format!("must be finite and > 0, got {fps}"),
            ));
        }
        for &(t, g) in goal_changes {
            if !(t.is_finite() && g.is_finite() && g > 0.0) {
                return Err(Error::invalid(
                    "goal_changes",
                    format!("({t}, {g}): times must be finite and goals > 0"),
                ));
            }
        }
        self.reset(goal)?;
        let dt = 1.0 / fps;
        let mut changes: Vec<(f64, f64)> = goal_changes.to_vec();
        changes.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut ci = 0;
        let mut frames = vec![self.frame()];
        while !self.finished {
            while ci < changes.len() && changes[ci].0 <= self.time + 1e-12 {
                self.set_goal(changes[ci].1)?;
                ci += 1;
            }
            if self.time > max_seconds {
                return Err(Error::LimitExceeded(format!(
                    "synthesis ran past {max_seconds} s without finishing"
                )));
            }
            self.step(dt)?;
            frames.push(self.frame());
        }
        Ok(Synthesis {
            frames,
            executed: self.executed.clone(),
            transitions: self.transitions.clone(),
            too_short: self.too_short,
        })
    }
}
