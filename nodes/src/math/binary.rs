//! The node state shared by the two-input arithmetic nodes (`add`, `mul`):
//! one operation applied sample by sample to inputs `a` and `b`.

use evflow_engine::ports::{InPort, OutPort};
use evflow_engine::{Io, Node, NodeError};

/// `v` held within ±f64::MAX: a sum or product of finite samples that
/// overflows saturates instead of leaving the node as ±∞ (every finite
/// value passes unchanged, bit for bit; found by `evflow report stability`).
#[inline]
pub fn saturate(v: f64) -> f64 {
    v.clamp(-f64::MAX, f64::MAX)
}

/// y[n] = op(a[n], b[n]), saturated ([`saturate`]); generic over the operation, so it is inlined.
pub struct Binary<F> {
    /// The node's first operand port.
    pub a: InPort,
    /// The node's second operand port.
    pub b: InPort,
    /// The node's result port.
    pub out: OutPort,
    /// The operation.
    pub op: F,
}

impl<F: Fn(f64, f64) -> f64 + Send> Node for Binary<F> {
    fn process(&mut self, io: &mut Io<'_>) -> Result<(), NodeError> {
        let n = io.len();
        for k in 0..n {
            let v = (self.op)(io.input(self.a)[k], io.input(self.b)[k]);
            io.output(self.out)[k] = saturate(v);
        }
        Ok(())
    }

    fn reset(&mut self) {}
}

#[cfg(test)]
mod tests {
    use evflow_engine::harness::Single;
    use evflow_engine::NodeSpec;

    fn run(spec: &'static NodeSpec, a: &[f64], b: &[f64]) -> Vec<f64> {
        Single::new(spec, "")
            .input("a", a.to_vec(), 1000.0)
            .input("b", b.to_vec(), 1000.0)
            .output("out")
            .ticks(a.len() as u64)
            .block(7)
            .run()
            .unwrap()
            .remove(0)
    }

    #[test]
    fn sums_and_products_beyond_f64_saturate() {
        let m = f64::MAX;
        let a = [m, -m, 1e300, 2.0, -m];
        let b = [m, -m, -1e300, 3.0, m];
        assert_eq!(run(&crate::math::add::SPEC, &a, &b), [m, -m, 0.0, 5.0, 0.0]);
        assert_eq!(run(&crate::math::mul::SPEC, &a, &b), [m, m, -m, 6.0, -m]);
    }

    #[test]
    fn add_and_mul_fold_constants() {
        use evflow_engine::spec::FoldArgs;
        let p = evflow_engine::Params::default();
        let (add, mul) = (&super::super::add::SPEC, &super::super::mul::SPEC);
        let at = |spec: &'static NodeSpec, a, b| {
            (spec.fold.unwrap())(&FoldArgs::new(spec, &p, &[a, b], 1, true)).map(|k| k.outputs[0].unwrap())
        };
        assert_eq!(at(add, Some(1.5), Some(-0.25)), Some(1.25));
        assert_eq!(at(add, Some(0.0), None), None);
        assert_eq!(at(mul, Some(1.5), Some(-2.0)), Some(-3.0));
        assert_eq!(at(mul, Some(0.0), None), Some(0.0));
        assert_eq!(at(mul, None, Some(0.0)), Some(0.0));
        assert_eq!(at(mul, None, Some(2.0)), None);
    }

    #[test]
    fn add_and_mul_work_sample_by_sample_across_blocks() {
        let a: Vec<f64> = (0..50).map(|i| i as f64 * 0.5).collect();
        let b: Vec<f64> = (0..50).map(|i| if i % 3 == 0 { -2.0 } else { 1e-17 }).collect();
        let sum = run(&super::super::add::SPEC, &a, &b);
        let product = run(&super::super::mul::SPEC, &a, &b);
        for k in 0..50 {
            assert_eq!(sum[k], a[k] + b[k]);
            assert_eq!(product[k], a[k] * b[k]);
        }
    }
}
