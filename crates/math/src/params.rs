//! The parameter-struct convention of the workspace.
//!
//! Every method takes its parameters as one `XxxParams` struct whose `Default` holds the
//! paper's values. The structs are declared through [`params!`](crate::params), which marks
//! them `#[non_exhaustive]` (adding a parameter later breaks no caller) and gives every field
//! a chainable setter of the same name, so callers outside the defining crate write
//!
//! ```
//! # use wscg_math::metrics::SsimParams;
//! let p = SsimParams::default().sigma(2.0).data_range(255.0);
//! assert_eq!((p.sigma, p.data_range), (2.0, 255.0));
//! ```
//!
//! instead of a struct literal (which `#[non_exhaustive]` forbids outside the crate). Fields
//! stay public for reading and for assignment (`p.sigma = 2.0`).

/// Declares a parameter struct: the struct as written, marked `#[non_exhaustive]`, plus one
/// chainable setter per field, named as the field and documented from its name.
///
/// ```
/// wscg_math::params! {
///     /// Parameters of a smoother.
///     #[derive(Clone, Debug, PartialEq)]
///     pub struct SmootherParams {
///         /// Iterations.
///         pub iterations: usize,
///         /// Step size.
///         pub step: f64,
///     }
/// }
/// impl Default for SmootherParams {
///     fn default() -> Self {
///         Self { iterations: 10, step: 0.5 }
///     }
/// }
/// let p = SmootherParams::default().step(0.25);
/// assert_eq!((p.iterations, p.step), (10, 0.25));
/// ```
#[macro_export]
macro_rules! params {
    (
        $(#[$meta:meta])*
        $vis:vis struct $name:ident {
            $(
                $(#[$fmeta:meta])*
                $fvis:vis $field:ident : $ty:ty
            ),* $(,)?
        }
    ) => {
        $(#[$meta])*
        #[non_exhaustive]
        $vis struct $name {
            $(
                $(#[$fmeta])*
                $fvis $field: $ty,
            )*
        }

        impl $name {
            $(
                #[doc = concat!(
                    "Returns these parameters with [`", stringify!($field), "`](Self::",
                    stringify!($field), ") set to `value`."
                )]
                #[must_use]
                #[inline]
                $fvis fn $field(mut self, value: $ty) -> Self {
                    self.$field = value;
                    self
                }
            )*
        }
    };
}
