pub use wscg_math as math;
