//! Layers, the recurrent Q-net and Adam (filled in by issue 3).
