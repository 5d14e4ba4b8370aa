//! The achievable floor (docs/synthesis.md): the E_s reached by optimizing
//! the actuation through the lab's own simulated display, noise off, from
//! several starts, u in [−1, 1] — what a renderer that only sees
//! recordings can approach but not pass.

use super::row::{Achievable, RowInputs};
use super::StudyError;

/// Computes the achievable floor of a row.
pub fn achievable(_i: &RowInputs<'_>) -> Result<Achievable, StudyError> {
    Err(StudyError::Config("the achievable floor is not available yet".into()))
}
