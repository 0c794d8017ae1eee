//! Reverse-mode automatic differentiation over `ndarray` (filled in by issue 3).
