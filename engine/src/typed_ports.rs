//! TRANSITION: the named port constants' old path; they live in [`crate::ports`].

pub use crate::ports::{InPort, OutPort};
