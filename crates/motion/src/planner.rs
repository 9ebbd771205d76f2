//! Predictive step planning (paper §2.5 and §3).
//!
//! The distance `D` from the pelvis to the drawer front is covered by walking steps so that the
//! final reach (action 3) starts at the comfort distance `D₃ = 0.6 m`. For a 3-action sequence
//! the paper splits the rest as `D₁ = γ (D − 0.6)`, `D₂ = (1 − γ)(D − 0.6)` with `γ = 0.385`.
//! Every length must lie inside the range of step lengths that action was trained on.
//!
//! The paper gives no formula for longer or shorter goals (§3 only says that steps are added
//! or removed automatically); ours:
//! - long goals get `n₁ ≥ 1` normal steps (action 1) and one shortened step (action 2) keeping
//!   `L₁ / L₂ = γ / (1 − γ)`: `L₂ = (D − 0.6) / (n₁ γ/(1−γ) + 1)`, `L₁ = L₂ γ/(1−γ)`;
//! - goals too short for that get `n₂ ≥ 1` shortened steps `L₂ = (D − 0.6) / n₂`;
//! - the feasible plan with the fewest steps wins; when none is feasible (the step ranges leave
//!   gaps), the plan with the smallest range violation is taken. Its lengths still sum to
//!   `D − 0.6` (the pelvis must arrive), and the weight regression clamps its queries to the
//!   trained range instead;
//! - goals closer than `0.6 m` plus the smallest trained step give an empty plan flagged
//!   `too_short` (not an error).
//!
//! Note: as printed, `γ = 0.385` gives the *first* action the smaller share, which conflicts
//! with "action 2 is a shortened step"; the formula is implemented as printed and `γ` is a
//! parameter.

use wscg_math::{Error, Result};

/// The three actions of the walk-and-reach task.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Action {
    /// A normal gait step (action 1).
    Step = 0,
    /// The shortened step before the reach (action 2).
    ShortStep = 1,
    /// Reaching into the drawer (action 3); the pelvis does not travel.
    Reach = 2,
}

impl Action {
    /// `0`, `1` or `2`.
    pub fn index(self) -> usize {
        self as usize
    }

    /// The action of an index.
    pub fn from_index(i: usize) -> Option<Self> {
        match i {
            0 => Some(Self::Step),
            1 => Some(Self::ShortStep),
            2 => Some(Self::Reach),
            _ => None,
        }
    }
}

/// One planned action and the distance the pelvis travels during it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlannedAction {
    /// Which action.
    pub action: Action,
    /// Pelvis travel (metres); 0 for the reach.
    pub length: f64,
}

/// A plan: the steps, then the reach.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Plan {
    /// Actions in order (the last one is the reach unless `too_short`).
    pub actions: Vec<PlannedAction>,
    /// The goal is closer than the comfort distance plus the smallest trained step: no steps.
    pub too_short: bool,
    /// Largest distance (metres) by which a step length leaves its trained range (0 when the
    /// plan is feasible).
    pub violation: f64,
}

impl Plan {
    /// Number of walking steps (actions 1 and 2).
    pub fn n_steps(&self) -> usize {
        self.actions
            .iter()
            .filter(|a| a.action != Action::Reach)
            .count()
    }

    /// Number of normal steps (action 1).
    pub fn n_normal_steps(&self) -> usize {
        self.actions
            .iter()
            .filter(|a| a.action == Action::Step)
            .count()
    }

    /// Total pelvis travel.
    pub fn distance(&self) -> f64 {
        self.actions.iter().map(|a| a.length).sum()
    }
}

/// The predictive planner of paper §2.5.
#[derive(Clone, Debug, PartialEq)]
pub struct Planner {
    /// Comfort distance of the reach `D₃` (metres).
    pub comfort: f64,
    /// Share `γ` of the first action.
    pub gamma: f64,
    /// Trained step-length range of action 1 (metres).
    pub range1: (f64, f64),
    /// Trained step-length range of action 2 (metres).
    pub range2: (f64, f64),
    /// `Some(L)`: the human-like variant in which normal steps keep the fixed length `L` and only
    /// the last step adapts (the human data of paper Fig. 2 show no dependence of the first step
    /// on the distance, R² = 0.08).
    pub human_like: Option<f64>,
    /// Upper bound on the number of steps of a plan.
    pub max_steps: usize,
}

impl Default for Planner {
    /// The paper's `D₃ = 0.6 m` and `γ = 0.385`, with the step ranges of the synthetic learning
    /// set ([`crate::walker`]), which reproduce the paper's 3-action interval `[2.34, 2.94]` m
    /// (§3).
    fn default() -> Self {
        Self {
            comfort: 0.6,
            gamma: 0.385,
            range1: (0.670, 0.901),
            range2: (1.070, 1.439),
            human_like: None,
            max_steps: 1000,
        }
    }
}

fn violation(len: f64, r: (f64, f64)) -> f64 {
    (r.0 - len).max(len - r.1).max(0.0)
}

/// A candidate plan of [`Planner::plan`]: `normal` steps of `l1` then `short` shortened
/// steps of `l2`, and its range violation.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    normal: usize,
    l1: f64,
    short: usize,
    l2: f64,
    violation: f64,
}

impl Candidate {
    fn len(&self) -> usize {
        self.normal + self.short
    }
}

impl Planner {
    /// Checks the parameters.
    ///
    /// # Errors
    /// Non-positive or non-finite comfort distance, `γ ∉ (0, 1)`, empty or non-positive ranges.
    pub fn validate(&self) -> Result<()> {
        if !(self.comfort.is_finite() && self.comfort >= 0.0) {
            return Err(Error::invalid(
                "comfort",
                format!("must be finite and >= 0, got {}", self.comfort),
            ));
        }
        if !(self.gamma > 0.0 && self.gamma < 1.0) {
            return Err(Error::invalid(
                "gamma",
                format!("must be in (0, 1), got {}", self.gamma),
            ));
        }
        for (name, r) in [("range1", self.range1), ("range2", self.range2)] {
            if !(r.0.is_finite() && r.1.is_finite() && r.0 > 0.0 && r.1 >= r.0) {
                return Err(Error::invalid(
                    name,
                    format!("must satisfy 0 < lo <= hi, got ({}, {})", r.0, r.1),
                ));
            }
        }
        if let Some(l) = self.human_like {
            if !(l.is_finite() && l > 0.0) {
                return Err(Error::invalid(
                    "human_like",
                    format!("step length must be > 0, got {l}"),
                ));
            }
        }
        if self.max_steps == 0 {
            return Err(Error::invalid("max_steps", "must be >= 1"));
        }
        Ok(())
    }

    /// Plans the approach to a goal at distance `d` (metres, pelvis to drawer front).
    ///
    /// # Errors
    /// `d` not finite or ≤ 0; invalid planner parameters; a goal that needs more than
    /// `max_steps` steps; [`Error::OutOfMemory`] naming `goal` for a plan beyond the memory
    /// limit; [`Error::Interrupted`] on a cancellation request ([`wscg_math::cancel`]).
    pub fn plan(&self, d: f64) -> Result<Plan> {
        self.validate()?;
        if !(d.is_finite() && d > 0.0) {
            return Err(Error::invalid(
                "goal",
                format!("distance must be finite and > 0, got {d}"),
            ));
        }
        let x = d - self.comfort;
        let shortest = self.range1.0.min(self.range2.0);
        if x < shortest {
            return Ok(Plan {
                actions: Vec::new(),
                too_short: true,
                violation: 0.0,
            });
        }
        let longest = self.range1.1.max(self.range2.1);
        let needed = (x / longest).ceil() as usize;
        if needed > self.max_steps {
            return Err(Error::LimitExceeded(format!(
                "a goal of {d} m needs at least {needed} steps (max_steps = {})",
                self.max_steps
            )));
        }
        // A plan has at least `needed` steps: refuse one that cannot be held before looking.
        wscg_math::alloc::ensure::<PlannedAction>("goal", needed.saturating_add(1))?;
        let n_max = ((x / shortest).ceil() as usize + 1).min(self.max_steps);
        // The candidates in order, each kept as its counts and lengths (a plan of n steps is
        // built only once chosen): the feasible one with the fewest steps, else the smallest
        // violation (then the fewest steps); the first of equals. Within each family the
        // lengths shrink as the count grows, so the violation (the larger of two functions of
        // the lengths that fall, stay at 0 inside the range, then rise) falls, then rises: a
        // family's scan ends at its first feasible plan (more steps follow) or once the
        // violation rises.
        let mut feasible: Option<Candidate> = None;
        let mut closest: Option<Candidate> = None;
        let mut consider = |c: Candidate| {
            if c.violation <= 1e-12 && feasible.is_none_or(|f| c.len() < f.len()) {
                feasible = Some(c);
            }
            let better = |b: &Candidate| {
                c.violation
                    .total_cmp(&b.violation)
                    .then(c.len().cmp(&b.len()))
                    .is_lt()
            };
            if closest.as_ref().is_none_or(better) {
                closest = Some(c);
            }
        };
        // Long goals: n1 normal steps and one shortened step.
        let mut normal_too_short = false;
        let mut any = false;
        let mut last = f64::INFINITY;
        for n1 in 1..n_max {
            if n1 % (1 << 16) == 0 {
                wscg_math::cancel::check()?;
            }
            let (l1, l2) = match self.human_like {
                Some(l1) => (l1, x - n1 as f64 * l1),
                None => {
                    let r = self.gamma / (1.0 - self.gamma);
                    let l2 = x / (n1 as f64 * r + 1.0);
                    (r * l2, l2)
                }
            };
            if l2 <= 0.0 {
                break;
            }
            if n1 == 1 && (l1 < self.range1.0 || l2 < self.range2.0) {
                normal_too_short = true;
            }
            any = true;
            let v = violation(l1, self.range1).max(violation(l2, self.range2));
            consider(Candidate {
                normal: n1,
                l1,
                short: 1,
                l2,
                violation: v,
            });
            if v <= 1e-12 || v > last {
                break;
            }
            last = v;
        }
        // Short goals: shortened steps only.
        if normal_too_short || !any {
            let mut last = f64::INFINITY;
            for n2 in 1..=n_max {
                if n2 % (1 << 16) == 0 {
                    wscg_math::cancel::check()?;
                }
                let l2 = x / n2 as f64;
                let v = violation(l2, self.range2);
                consider(Candidate {
                    normal: 0,
                    l1: 0.0,
                    short: n2,
                    l2,
                    violation: v,
                });
                if v <= 1e-12 || v > last {
                    break;
                }
                last = v;
            }
        }
        let c = feasible
            .or(closest)
            .ok_or_else(|| Error::Numerical(format!("no plan for a goal of {d} m")))?;
        let step = |a: Action, l: f64| PlannedAction {
            action: a,
            length: l,
        };
        let mut actions = wscg_math::alloc::try_with_capacity("goal", c.len() + 1)?;
        actions.extend(std::iter::repeat_n(step(Action::Step, c.l1), c.normal));
        actions.extend(std::iter::repeat_n(step(Action::ShortStep, c.l2), c.short));
        let v = c.violation;
        actions.push(step(Action::Reach, 0.0));
        Ok(Plan {
            actions,
            too_short: false,
            violation: v,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every candidate of both families, chosen by the rules of [`Planner::plan`] without its
    /// early ends: the feasible plan with the fewest steps, else the smallest violation then
    /// the fewest steps, the first of equals.
    fn exhaustive(p: &Planner, d: f64) -> (usize, usize, f64) {
        let x = d - p.comfort;
        let shortest = p.range1.0.min(p.range2.0);
        let n_max = ((x / shortest).ceil() as usize + 1).min(p.max_steps);
        let mut all: Vec<(usize, usize, f64)> = Vec::new();
        let mut too_short = false;
        for n1 in 1..n_max {
            let (l1, l2) = match p.human_like {
                Some(l1) => (l1, x - n1 as f64 * l1),
                None => {
                    let r = p.gamma / (1.0 - p.gamma);
                    let l2 = x / (n1 as f64 * r + 1.0);
                    (r * l2, l2)
                }
            };
            if l2 <= 0.0 {
                break;
            }
            too_short |= n1 == 1 && (l1 < p.range1.0 || l2 < p.range2.0);
            let v = violation(l1, p.range1).max(violation(l2, p.range2));
            all.push((n1, 1, v));
        }
        if too_short || all.is_empty() {
            for n2 in 1..=n_max {
                all.push((0, n2, violation(x / n2 as f64, p.range2)));
            }
        }
        let len = |c: &(usize, usize, f64)| c.0 + c.1;
        all.iter()
            .filter(|c| c.2 <= 1e-12)
            .min_by_key(|c| len(c))
            .or_else(|| {
                all.iter()
                    .min_by(|a, b| a.2.total_cmp(&b.2).then(len(a).cmp(&len(b))))
            })
            .copied()
            .unwrap()
    }

    #[test]
    fn the_early_ends_choose_what_every_candidate_would() {
        let planners = [
            Planner::default(),
            Planner {
                human_like: Some(0.8),
                ..Planner::default()
            },
            Planner {
                human_like: Some(1.6),
                ..Planner::default()
            },
            Planner {
                gamma: 0.7,
                range1: (0.1, 0.2),
                range2: (0.9, 1.0),
                ..Planner::default()
            },
            Planner {
                range1: (1.5, 1.6),
                range2: (0.3, 0.35),
                max_steps: 40,
                ..Planner::default()
            },
        ];
        for p in &planners {
            for k in 1..400 {
                let d = 0.05 * k as f64;
                let Ok(plan) = p.plan(d) else {
                    continue;
                };
                if plan.too_short {
                    continue;
                }
                let (normal, short, v) = exhaustive(p, d);
                assert_eq!(
                    (
                        plan.n_normal_steps(),
                        plan.n_steps() - plan.n_normal_steps()
                    ),
                    (normal, short),
                    "{p:?} d = {d}"
                );
                assert_eq!(plan.violation, v, "{p:?} d = {d}");
            }
        }
    }

    #[test]
    fn a_goal_whose_plan_cannot_be_held_is_refused_at_once() {
        let p = Planner {
            max_steps: usize::MAX,
            ..Planner::default()
        };
        let e = p.plan(1e15).unwrap_err();
        assert!(matches!(e, Error::OutOfMemory { what: "goal", .. }), "{e}");
        // A long goal that fits is planned: 5 km in normal steps of at most 0.901 m (action
        // 1's range).
        let plan = p.plan(5000.0).unwrap();
        assert!(plan.n_steps() >= 5549 && plan.violation == 0.0);
        assert!((plan.distance() - (5000.0 - p.comfort)).abs() < 1e-6);
    }
}
