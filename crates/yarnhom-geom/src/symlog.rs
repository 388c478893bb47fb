//! The symmetric logarithm of App. A.3.3: the space in which the fit smooths sampled energies
//! (A.35) and in which its figures colour them (Fig. 4.5). One definition for both.

/// `sgn(x) ln(|x| + 1)` (App. A.3.3).
pub fn symlog(x: f64) -> f64 {
    x.signum() * x.abs().ln_1p()
}

/// `sgn(x) (exp(|x|) - 1)`, the inverse of [`symlog`] (App. A.3.3).
pub fn symexp(x: f64) -> f64 {
    x.signum() * x.abs().exp_m1()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn symlog_and_symexp_are_inverse() {
        for x in [-1e6, -30.0, -1.0, -1e-12, 0.0, 1e-9, 0.5, 7.0, 1e5] {
            assert!((symexp(symlog(x)) - x).abs() <= 1e-13 * x.abs().max(1e-300), "{x}");
            assert!(
                (symlog(symexp(x.clamp(-700.0, 700.0))) - x.clamp(-700.0, 700.0)).abs()
                    <= 1e-12 * x.abs().max(1.0)
            );
        }
        assert_eq!(symlog(-3.0), -symlog(3.0));
        assert!((symlog(std::f64::consts::E - 1.0) - 1.0).abs() < 1e-15);
    }
}
