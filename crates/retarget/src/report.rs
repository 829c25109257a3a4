//! Motion quality metrics.
