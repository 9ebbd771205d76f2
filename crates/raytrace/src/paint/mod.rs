//! Metallic-flake paint (paper 07, sections 2.2-2.3).
