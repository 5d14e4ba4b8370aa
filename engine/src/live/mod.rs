//! The live runner (in progress).
