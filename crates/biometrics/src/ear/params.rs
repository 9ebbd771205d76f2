//! Parameters of the ear pipeline ([`EarParams`]) with the paper's values, the block shifts
//! of eqs. 8-16 and the score rules of eqs. 17-18 (Fig. 11).

use wscg_math::{Error, Result};

use super::skin::{SkinModel, SkinRule};

/// The nine block shifts `(d_row, d_col)` of eqs. 8-16, in the paper's order `B0 .. B8`
/// (Fig. 9): probe block `(i, j)` is compared with enrolled block `(i + d_row, j + d_col)`.
pub const SHIFTS_NINE: [(i32, i32); 9] = [
    (0, 0),
    (0, 1),
    (1, 1),
    (1, 0),
    (1, -1),
    (0, -1),
    (-1, -1),
    (-1, 0),
    (-1, 1),
];

/// How the per-shift, per-block similarities `s_{s,j} = 1 - d_{s,j}` become one score.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ScoreRule {
    /// `S_B = (1/m) sum_j max_s s_{s,j}`: the block-wise maximum (the paper's best rule;
    /// our reading of eq. 18).
    #[default]
    BlockwiseMax,
    /// `S_m = max_s S_s` over the shifts whose score is defined (eq. 17).
    OverallMax,
    /// `(1/m) sum_j mean_s s_{s,j}`.
    BlockwiseMean,
    /// The mean of the defined per-shift scores `S_s`.
    OverallMean,
    /// `max_{s,j} s_{s,j}`: eq. 18 as printed, a single best block (degenerate; kept to show
    /// why it is not used).
    LiteralEq18,
}

impl ScoreRule {
    /// All rules, in the order of Fig. 11 followed by the literal eq. 18.
    pub const ALL: [ScoreRule; 5] = [
        ScoreRule::BlockwiseMax,
        ScoreRule::OverallMax,
        ScoreRule::BlockwiseMean,
        ScoreRule::OverallMean,
        ScoreRule::LiteralEq18,
    ];

    /// Parses `blockwise-max`, `overall-max`, `blockwise-mean`, `overall-mean`, `literal-eq18`
    /// (underscores accepted).
    pub fn parse(name: &str) -> Result<Self> {
        match name.to_ascii_lowercase().replace('_', "-").as_str() {
            "blockwise-max" => Ok(ScoreRule::BlockwiseMax),
            "overall-max" => Ok(ScoreRule::OverallMax),
            "blockwise-mean" => Ok(ScoreRule::BlockwiseMean),
            "overall-mean" => Ok(ScoreRule::OverallMean),
            "literal-eq18" => Ok(ScoreRule::LiteralEq18),
            _ => Err(Error::invalid(
                "score",
                format!(
                    "unknown rule {name:?}; use blockwise-max, overall-max, blockwise-mean, \
                     overall-mean or literal-eq18"
                ),
            )),
        }
    }

    /// Position of the rule in [`Self::ALL`].
    pub fn index(self) -> usize {
        self as usize
    }

    /// The name [`Self::parse`] accepts.
    pub fn name(self) -> &'static str {
        match self {
            ScoreRule::BlockwiseMax => "blockwise-max",
            ScoreRule::OverallMax => "overall-max",
            ScoreRule::BlockwiseMean => "blockwise-mean",
            ScoreRule::OverallMean => "overall-mean",
            ScoreRule::LiteralEq18 => "literal-eq18",
        }
    }
}

wscg_math::params! {
    /// Parameters of enrolment, occlusion detection (Algorithm 1) and matching (eqs. 7-18).
    /// `Default` holds the paper's values; the skin model is ours (the paper cites one without
    /// numbers), fit your own with [`SkinModel::fit`] on enrolment images.
    #[derive(Clone, Debug, PartialEq)]
    pub struct EarParams {
        /// Rows of the normalised ear image (paper: 100).
        pub height: usize,
        /// Columns of the normalised ear image (paper: 80).
        pub width: usize,
        /// Block side in pixels (paper: 10, giving 10 x 8 = 80 blocks); must be even and divide
        /// both sizes.
        pub block: usize,
        /// Skin colour model in normalised `(r, g)` (eqs. 2-5).
        pub skin_model: SkinModel,
        /// Per-pixel skin decision (paper steps 5-6; default the paper's AND of the two marginal
        /// likelihoods, see [`SkinRule`]).
        pub skin_rule: SkinRule,
        /// Luminance gate (not in the paper): skin also needs `(R + G + B) / 3 >= min_intensity`.
        /// 0 (default) is the paper; about 35 rejects dark hair, whose chromaticity is skin-like.
        pub min_intensity: u8,
        /// Radius of the closing disk in pixels of the normalised image (paper step 7: 10).
        pub close_radius: f64,
        /// Fill holes of the closed skin mask (background not 4-connected to the border).
        pub fill_holes: bool,
        /// A block is un-occluded when at least this fraction of its pixels is skin (0, 1].
        pub block_skin_fraction: f64,
        /// Probes with more than this percentage of occluded blocks are rejected (step 12: 60).
        pub reject_above_pct: f64,
        /// Block shifts tried when matching (default: the nine of eqs. 8-16).
        pub shifts: Vec<(i32, i32)>,
        /// Score rule (default: block-wise maximum).
        pub score: ScoreRule,
        /// Extract probe features from the masked image `X = Y . Z` (step 8) instead of `Y`.
        pub mask_features: bool,
        /// Accept single-channel images at enrolment (no colour is needed there).
        pub gray_enrolment: bool,
        /// Equalise a probe with the histogram of its detected skin pixels only (default
        /// `true`; not in the paper). `false` is the paper's pre-processing (step 2: the whole
        /// probe is equalised before occlusion is detected): a large occluder then shifts the
        /// equalised grey levels of the visible ear, the kept blocks no longer match their
        /// templates, and on occluded probes index-based matching loses to the whole-ear
        /// baseline (BENCHMARKS.md, paper 14). Both cost the same: one histogram pass.
        pub equalize_on_skin: bool,
    }
}

impl Default for EarParams {
    fn default() -> Self {
        EarParams {
            height: 100,
            width: 80,
            block: 10,
            skin_model: SkinModel::default(),
            skin_rule: SkinRule::default(),
            min_intensity: 0,
            close_radius: 10.0,
            fill_holes: true,
            block_skin_fraction: 0.5,
            reject_above_pct: 60.0,
            shifts: SHIFTS_NINE.to_vec(),
            score: ScoreRule::BlockwiseMax,
            mask_features: false,
            gray_enrolment: false,
            equalize_on_skin: true,
        }
    }
}

impl EarParams {
    /// Checks every field; the error names the offending one.
    pub fn validate(&self) -> Result<()> {
        if self.block == 0 || self.block % 2 == 1 {
            return Err(Error::invalid(
                "block",
                format!(
                    "must be even and > 0 (the Haar LL halves it), got {}",
                    self.block
                ),
            ));
        }
        if self.height == 0
            || self.width == 0
            || !self.height.is_multiple_of(self.block)
            || !self.width.is_multiple_of(self.block)
        {
            return Err(Error::invalid(
                "block",
                format!(
                    "{} does not divide the normalised size {} x {}",
                    self.block, self.height, self.width
                ),
            ));
        }
        if self.blocks() > u16::MAX as usize {
            return Err(Error::invalid(
                "block",
                format!("{} blocks is too many", self.blocks()),
            ));
        }
        self.skin_model.validate()?;
        self.skin_rule.validate()?;
        if !(self.close_radius.is_finite() && self.close_radius >= 0.0) {
            return Err(Error::invalid(
                "close_radius",
                format!("must be finite and >= 0, got {}", self.close_radius),
            ));
        }
        if !(self.block_skin_fraction > 0.0 && self.block_skin_fraction <= 1.0) {
            return Err(Error::invalid(
                "block_skin_fraction",
                format!("must lie in (0, 1], got {}", self.block_skin_fraction),
            ));
        }
        if !self.reject_above_pct.is_finite() {
            return Err(Error::invalid("reject_above_pct", "must be finite"));
        }
        if self.shifts.is_empty() {
            return Err(Error::invalid("shifts", "needs at least one shift"));
        }
        Ok(())
    }

    /// Checks that `blocks x block_len` features (of a `what`: template, gallery) fit these
    /// parameters.
    pub fn check_layout(&self, what: &str, blocks: usize, block_len: usize) -> Result<()> {
        if blocks != self.blocks() || block_len != self.block_len() {
            return Err(Error::ShapeMismatch(format!(
                "{what} has {blocks} blocks x {block_len} features, the parameters need {} x {}",
                self.blocks(),
                self.block_len()
            )));
        }
        Ok(())
    }

    /// Block grid `(rows, cols)` (paper: 10 x 8).
    pub fn grid(&self) -> (usize, usize) {
        (self.height / self.block, self.width / self.block)
    }

    /// Number of blocks (paper: 80).
    pub fn blocks(&self) -> usize {
        let (r, c) = self.grid();
        // Saturating: sizes read from a file are checked against a bound with this.
        r.saturating_mul(c)
    }

    /// Features per block: the `block/2 x block/2` Haar LL (paper: 25).
    pub fn block_len(&self) -> usize {
        (self.block / 2).saturating_mul(self.block / 2)
    }

    /// Upper bound of a block distance, `2 sqrt(block_len)` (LL values lie in `[0, 2]`): it
    /// scales the Euclidean block distance of eq. 7 into `[0, 1]`, which the similarities
    /// `S = 1 - D` of eqs. 8-16 need (the paper does not normalise `D`).
    pub fn distance_scale(&self) -> f64 {
        2.0 * (self.block_len() as f64).sqrt()
    }
}
