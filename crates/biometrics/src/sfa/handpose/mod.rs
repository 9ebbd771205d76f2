//! Synthetic hand poses and their physical features (in progress).
