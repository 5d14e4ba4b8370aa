//! Adam training (placeholder until written).
