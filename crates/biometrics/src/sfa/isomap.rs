//! Isomap (in progress).
