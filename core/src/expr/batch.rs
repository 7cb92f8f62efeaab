//! Batch evaluation: one pass over the tape computes up to `L` points per
//! instruction, so the per-instruction dispatch cost (an indirect jump and a
//! store/load round trip through the register file, several nanoseconds) is paid once
//! per `L` points instead of once per point, and the simple arithmetic loops
//! vectorise.
//!
//! The register file is `N` rows of `L` lanes on the stack (`N·L·8` bytes: 4 KiB for
//! small tapes, 16 KiB at most). Lanes past the end of the last, partial chunk hold
//! stale values; they are computed and discarded, which is harmless for `f64`.

use super::ops::{Op, b2f, truthy};
use super::tape::{Instr, MAX_REGS, Tape};

impl Tape {
    /// Evaluates the points `k` given by `columns[slot][k]`, writing `out[k]`.
    pub(crate) fn eval_batch(&self, columns: &[&[f64]], out: &mut [f64]) {
        match self.regs {
            0..=8 => run_batch::<8, 64>(&self.instrs, self.result, columns, out),
            9..=32 => run_batch::<32, 32>(&self.instrs, self.result, columns, out),
            _ => run_batch::<MAX_REGS, 16>(&self.instrs, self.result, columns, out),
        }
    }
}

fn run_batch<const N: usize, const L: usize>(
    code: &[Instr],
    result: u8,
    columns: &[&[f64]],
    out: &mut [f64],
) {
    let mut regs = [[0.0f64; L]; N];
    for (chunk, dst) in out.chunks_mut(L).enumerate() {
        let (base, n) = (chunk * L, dst.len());
        for ins in code {
            if ins.op == Op::Var {
                let src = &columns[ins.a as usize][base..base + n];
                regs[ins.out as usize % N][..n].copy_from_slice(src);
            } else {
                let t = step(ins, &regs);
                regs[ins.out as usize % N] = t;
            }
        }
        dst.copy_from_slice(&regs[result as usize % N][..n]);
    }
}

/// One instruction over all lanes. Common operations get their own loops (the
/// arithmetic ones vectorise); everything else applies [`Op::apply`] per lane. Each
/// specialised loop computes exactly what [`Op::apply`] does for that operation.
#[inline]
fn step<const N: usize, const L: usize>(ins: &Instr, regs: &[[f64; L]; N]) -> [f64; L] {
    let a = &regs[ins.a as usize % N];
    let b = &regs[ins.b as usize % N];
    let imm = ins.imm;
    let mut t = [0.0f64; L];
    macro_rules! lanes {
        (|$x:ident| $e:expr) => {
            for (o, &$x) in t.iter_mut().zip(a) {
                *o = $e;
            }
        };
        (|$x:ident, $y:ident| $e:expr) => {
            for ((o, &$x), &$y) in t.iter_mut().zip(a).zip(b) {
                *o = $e;
            }
        };
    }
    match ins.op {
        Op::Const => t = [imm; L],
        Op::AddC => lanes!(|x| x + imm),
        Op::SubCR => lanes!(|x| imm - x),
        Op::MulC => lanes!(|x| x * imm),
        Op::DivRC => lanes!(|x| x / imm),
        Op::DivCR => lanes!(|x| imm / x),
        Op::MinC => lanes!(|x| x.min(imm)),
        Op::MaxC => lanes!(|x| x.max(imm)),
        Op::ClampLoC => lanes!(|x| if x < imm { imm } else { x }),
        Op::ClampHiC => lanes!(|x| if x > imm { imm } else { x }),
        Op::Neg => lanes!(|x| -x),
        Op::Abs => lanes!(|x| x.abs()),
        Op::Square => lanes!(|x| x * x),
        Op::Sqrt => lanes!(|x| x.sqrt()),
        Op::Add => lanes!(|x, y| x + y),
        Op::Sub => lanes!(|x, y| x - y),
        Op::Mul => lanes!(|x, y| x * y),
        Op::Div => lanes!(|x, y| x / y),
        Op::Min => lanes!(|x, y| x.min(y)),
        Op::Max => lanes!(|x, y| x.max(y)),
        Op::Lt => lanes!(|x, y| b2f(x < y)),
        Op::Gt => lanes!(|x, y| b2f(x > y)),
        // Common transcendentals: a direct call per lane, without the per-lane match.
        Op::Sin => lanes!(|x| x.sin()),
        Op::Cos => lanes!(|x| x.cos()),
        Op::Exp => lanes!(|x| x.exp()),
        Op::Ln => lanes!(|x| x.ln()),
        Op::Floor => lanes!(|x| crate::fastmath::floor(x)),
        Op::PowC => lanes!(|x| x.powf(imm)),
        Op::Select => {
            let c = &regs[ins.c as usize % N];
            for (l, o) in t.iter_mut().enumerate() {
                *o = if truthy(a[l]) { b[l] } else { c[l] };
            }
        }
        op => {
            let c = &regs[ins.c as usize % N];
            for (l, o) in t.iter_mut().enumerate() {
                *o = op.apply(a[l], b[l], c[l], imm);
            }
        }
    }
    t
}
