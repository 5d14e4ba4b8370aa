//! NARX models of the display (dissertation chapter 5): the network
//! ([`net`], Eq. 5.1), min–max normalization as MATLAB's `mapminmax`
//! ([`mapminmax`]) and its trainers ([`train`]: Levenberg–Marquardt as
//! `trainlm`, and Adam). The inverse-model nodes, model files and graphs
//! build on these.

pub mod mapminmax;
pub mod net;
pub mod train;
