//! Which constants of the emitted code are finite in `f64`.
//!
//! A constant can be finite as a number and still overflow where the
//! generated code evaluates it: `E.powi(710)` is the finite base `e` under
//! the exponent 710, kept symbolic because its value is not representable,
//! and generated code computes `∞` for it at run time (the Jacobian and
//! `linearize` then hold NaN). So every constant subexpression is evaluated
//! here as generated code evaluates it (`crate::emit`), and bounded where
//! the emitted order of operations is not fixed:
//!
//! - a number, and the coefficient of a sum's term or a product's exponent
//!   (`crate::expr::Graph::constants`), must be finite;
//! - a function of constants (`exp(1000)`, `ln(0)`, `asin(2)`) and a power
//!   with a variable exponent of constants must have a finite value;
//! - in a product, each constant factor is written as a power of its base
//!   (`b.powi(k)`, `b.sqrt()`, `b.powf(e)`; a negative exponent as a
//!   divisor `b.powi(−k)`), which must be finite (`(−1)^(1/2)` is NaN);
//!   the constant factors of the numerator and of the denominator are
//!   multiplied in an order that sharing may change, so the product of
//!   those of magnitude above 1 must be finite, and the product of the
//!   denominator's below 1 must not underflow to zero (a division by 0);
//! - in a sum, each constant term times its coefficient must be finite,
//!   and so must the sum of the magnitudes of the constant parts (whatever
//!   order they are added in, no partial sum exceeds it).
//!
//! A constant node whose value as a whole is not finite is reported too.
//! The bounds are sound (what passes cannot overflow in the emitted code)
//! and tight where it matters: they reject only products and sums whose
//! exact value, or that of a part the code computes, exceeds `f64`.

use crate::expr::num::Num;
use crate::expr::{power, Graph, Id, Node};

/// A constant subexpression that is not finite where generated code
/// evaluates it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NonFinite {
    /// The node that holds it (a constant node, or the sum or product one
    /// of whose constant parts overflows).
    pub node: Id,
    /// The offending value (`±∞` or NaN).
    pub value: f64,
}

/// Every constant subexpression of `g` (in arena order) that is not finite
/// in `f64` as generated code evaluates it: the nodes themselves, or the
/// sums and products one of whose constant parts is not.
pub fn non_finite(g: &Graph) -> Vec<NonFinite> {
    // The value of each constant node; `None` for nodes with variables
    // (and for those already reported).
    let mut value: Vec<Option<f64>> = Vec::with_capacity(g.len());
    let mut found = Vec::new();
    for id in g.ids() {
        match node_value(g, id, &value) {
            Ok(own) => value.push(own),
            Err(bad) => {
                found.push(bad);
                value.push(None);
            }
        }
    }
    found
}

/// The value of `id` where it is constant (`None` where it has variables),
/// given those of the nodes before it, or what of it is not finite.
fn node_value(g: &Graph, id: Id, value: &[Option<f64>]) -> Result<Option<f64>, NonFinite> {
    let own = match g.node(id) {
        Node::Num(n) => Some(n.to_f64()),
        Node::Sym(_) => None,
        Node::Add(terms, c0) => sum_value(id, terms, c0.to_f64(), value)?,
        Node::Mul(factors) => product_value(id, factors, value)?,
        Node::Pow([b, x]) => match (value[b.index()], value[x.index()]) {
            (Some(b), Some(x)) => Some(b.powf(x)),
            _ => None,
        },
        Node::Func(f, args) => {
            let mut values = [0.0; 2];
            let mut constant = true;
            for (v, a) in values.iter_mut().zip(args.as_slice()) {
                match value[a.index()] {
                    Some(x) => *v = x,
                    None => constant = false,
                }
            }
            constant.then(|| f.eval(&values[..f.arity()]))
        }
    };
    if let Some(v) = own {
        finite(id, v)?;
    }
    Ok(own)
}

/// `Ok` where `v` is finite, else `v` reported as the value of `id` that
/// is not.
fn finite(id: Id, v: f64) -> Result<(), NonFinite> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(NonFinite { node: id, value: v })
    }
}

/// The value of the sum `id` = `Σ cᵢ·tᵢ + c₀` where it is constant, after
/// checking that each constant term and the sum of the constant parts'
/// magnitudes are finite (no partial sum, in whatever order the emitted code
/// adds, exceeds that bound).
fn sum_value(
    id: Id,
    terms: &[(Id, Num)],
    c0: f64,
    value: &[Option<f64>],
) -> Result<Option<f64>, NonFinite> {
    let mut bound = c0.abs();
    let mut sum = Some(c0);
    for &(t, c) in terms {
        match value[t.index()] {
            Some(v) => {
                let term = c.to_f64() * v;
                finite(id, term)?;
                bound += term.abs();
                sum = sum.map(|s| s + term);
            }
            None => sum = None,
        }
    }
    finite(id, bound)?;
    Ok(sum)
}

/// The value of the product `id` = `Π bᵢ^eᵢ` where it is constant, after
/// checking each constant factor as emitted (the base under the exponent's
/// magnitude, a divisor where the exponent is negative), the product of the
/// numerator's and of the denominator's factors above 1 in magnitude, and
/// that the denominator's factors below 1 do not underflow to zero: sharing
/// may change the order in which they are multiplied.
fn product_value(
    id: Id,
    factors: &[(Id, Num)],
    value: &[Option<f64>],
) -> Result<Option<f64>, NonFinite> {
    let (mut big_num, mut big_den, mut small_den) = (1.0f64, 1.0f64, 1.0f64);
    let mut product = Some((1.0f64, 1.0f64));
    for &(b, e) in factors {
        let Some(base) = value[b.index()] else {
            product = None;
            continue;
        };
        let divides = e.is_negative();
        let magnitude = if divides { -e } else { e };
        let p = power(base, magnitude);
        finite(id, p)?;
        if divides {
            big_den *= p.abs().max(1.0);
            small_den *= p.abs().min(1.0);
        } else {
            big_num *= p.abs().max(1.0);
        }
        product = product.map(|(n, d)| if divides { (n, d * p) } else { (n * p, d) });
    }
    finite(id, big_num)?;
    finite(id, big_den)?;
    if small_den == 0.0 {
        return Err(NonFinite {
            node: id,
            value: f64::INFINITY,
        });
    }
    Ok(product.map(|(n, d)| n / d))
}
