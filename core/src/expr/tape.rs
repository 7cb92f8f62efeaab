//! Code generation and the evaluation loops: the folded tree becomes a flat tape of
//! register instructions, run by a `match` per instruction over a fixed-size register
//! file on the stack (no allocation per evaluation).
//!
//! Pipeline:
//!
//! 1. **SSA with value numbering.** Each tree node becomes one instruction producing
//!    a new value; identical instructions (same op, operands, immediate) are shared,
//!    so `sin(x)*sin(x)` computes `sin(x)` once and variables are loaded once.
//!    Operations with one constant operand use the `...C` forms with the constant in
//!    the instruction (`x/15 + 0.5` is `var; div_rc 15; add_c 0.5`), `clamp` with
//!    constant bounds becomes `clamp_lo_c; clamp_hi_c`, and `a*a` becomes `square`.
//! 2. **Sethi–Ullman ordering.** Children needing more registers are emitted first,
//!    so a right-leaning chain `a+(b+(c+...))` needs 2 registers, not one per level.
//! 3. **Linear-scan register allocation.** A value's register is freed after its last
//!    use and reused; an instruction may write the register of an operand it just
//!    read, because the evaluator reads all operands before writing.
//!
//! The register file has [`MAX_REGS`] entries; the evaluator picks the smallest of 8,
//! 32 or 128 registers that fits, so small expressions zero less stack per call.
//! Register indices are masked with `& (N - 1)` (N a power of two): always in range,
//! so the hot loop has no bounds checks and no `unsafe`.

use std::collections::HashMap;
use std::fmt;

use super::ast::Node;
use super::ops::Op;
use crate::interval::Interval;

/// Most registers an expression may need; compile fails beyond this.
pub(crate) const MAX_REGS: usize = 128;

/// One instruction: 16 bytes, constants inline.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Instr {
    /// The operation.
    pub op: Op,
    /// Destination register.
    pub out: u8,
    /// First operand register (the slot index for [`Op::Var`]).
    pub a: u8,
    /// Second operand register.
    pub b: u8,
    /// Third operand register.
    pub c: u8,
    /// Immediate constant for [`Op::Const`] and the `...C` forms.
    pub imm: f64,
}

/// A compiled expression: instructions, the register holding the result, and the
/// number of registers used.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Tape {
    /// Instructions in execution order.
    pub instrs: Box<[Instr]>,
    /// Register that holds the result after the last instruction.
    pub result: u8,
    /// Number of distinct registers written.
    pub regs: usize,
}

/// Returned when an expression needs more than [`MAX_REGS`] registers.
#[derive(Debug, PartialEq)]
pub(crate) struct TooManyRegisters;

/// One SSA instruction: operands are earlier value numbers (for `Var`, `args[0]` is
/// the slot).
#[derive(Clone, Copy)]
struct Ssa {
    op: Op,
    args: [u32; 3],
    imm: f64,
}

#[derive(Default)]
struct Builder {
    code: Vec<Ssa>,
    seen: HashMap<(Op, [u32; 3], u64), u32>,
}

/// `1/c` when `x / c == x * (1/c)` for every `x`: both `c` and `1/c` are normal
/// powers of two, so both sides round the same exact real number.
fn exact_reciprocal(c: f64) -> Option<f64> {
    const MANTISSA: u64 = (1 << 52) - 1;
    let r = 1.0 / c;
    (c.is_normal() && r.is_normal() && c.to_bits() & MANTISSA == 0 && r.to_bits() & MANTISSA == 0)
        .then_some(r)
}

/// Registers needed to evaluate `n` (Sethi–Ullman number): children sorted by
/// decreasing need, child `i` evaluated while `i` earlier results are held.
fn need(n: &Node) -> usize {
    match n {
        Node::Num(_) | Node::Var(_) => 1,
        Node::Apply { args, .. } => {
            let mut needs: Vec<usize> = args.iter().map(need).collect();
            needs.sort_unstable_by(|a, b| b.cmp(a));
            needs
                .iter()
                .enumerate()
                .map(|(i, k)| k + i)
                .max()
                .unwrap_or(1)
                .max(1)
        }
    }
}

impl Builder {
    /// Appends an instruction, or returns the value number of an identical one.
    fn push(&mut self, op: Op, mut args: [u32; 3], imm: f64) -> u32 {
        if op.is_commutative() && args[0] > args[1] {
            args.swap(0, 1);
        }
        self.push_as_is(op, args, imm)
    }

    /// [`Self::push`] keeping the operands' order (a minimum of `-0` and
    /// `+0` depends on it).
    fn push_as_is(&mut self, op: Op, args: [u32; 3], imm: f64) -> u32 {
        let key = (op, args, imm.to_bits());
        if let Some(&v) = self.seen.get(&key) {
            return v;
        }
        let v = self.code.len() as u32;
        self.code.push(Ssa { op, args, imm });
        self.seen.insert(key, v);
        v
    }

    fn unary_c(&mut self, op: Op, x: &Node, imm: f64) -> u32 {
        let a = self.emit(x);
        self.push(op, [a, 0, 0], imm)
    }

    fn emit(&mut self, n: &Node) -> u32 {
        let (op, args) = match n {
            Node::Num(v) => return self.push(Op::Const, [0; 3], *v),
            Node::Var(i) => return self.push(Op::Var, [u32::from(*i), 0, 0], 0.0),
            Node::Apply { op, args, .. } => (*op, args.as_slice()),
        };
        let num = Node::as_num;
        match (op, args) {
            (Op::Add, [x, k]) | (Op::Add, [k, x]) if num(k).is_some() && num(x).is_none() => {
                return self.unary_c(Op::AddC, x, num(k).unwrap_or(0.0));
            }
            (Op::Sub, [x, k]) if num(k).is_some() => {
                return self.unary_c(Op::AddC, x, -num(k).unwrap_or(0.0));
            }
            (Op::Sub, [k, x]) if num(k).is_some() => {
                return self.unary_c(Op::SubCR, x, num(k).unwrap_or(0.0));
            }
            (Op::Mul, [x, k]) | (Op::Mul, [k, x]) if num(k).is_some() && num(x).is_none() => {
                return self.unary_c(Op::MulC, x, num(k).unwrap_or(0.0));
            }
            (Op::Div, [x, k]) if num(k).is_some() => {
                let c = num(k).unwrap_or(0.0);
                return match exact_reciprocal(c) {
                    Some(r) => self.unary_c(Op::MulC, x, r),
                    None => self.unary_c(Op::DivRC, x, c),
                };
            }
            (Op::Div, [k, x]) if num(k).is_some() => {
                return self.unary_c(Op::DivCR, x, num(k).unwrap_or(0.0));
            }
            (Op::Min | Op::Max, [x, k]) | (Op::Min | Op::Max, [k, x])
                if num(k).is_some() && num(x).is_none() =>
            {
                let form = if op == Op::Min { Op::MinC } else { Op::MaxC };
                return self.unary_c(form, x, num(k).unwrap_or(0.0));
            }
            (Op::Pow, [x, k]) if num(k).is_some() => {
                return self.unary_c(Op::PowC, x, num(k).unwrap_or(0.0));
            }
            (Op::Clamp, [lo, x, hi]) => {
                if let (Some(lo), Some(hi)) = (num(lo), num(hi))
                    && lo <= hi
                {
                    let low = self.unary_c(Op::ClampLoC, x, lo);
                    return self.push(Op::ClampHiC, [low, 0, 0], hi);
                }
            }
            _ => {}
        }
        // Generic form: emit children, most register-hungry first.
        let mut order: Vec<usize> = (0..args.len()).collect();
        order.sort_by_key(|&i| std::cmp::Reverse(need(&args[i])));
        let mut ids = [0u32; 3];
        for i in order {
            ids[i] = self.emit(&args[i]);
        }
        if op == Op::Mul && ids[0] == ids[1] {
            return self.push(Op::Square, [ids[0], 0, 0], 0.0);
        }
        self.push(op, ids, 0.0)
    }
}

/// Compiles a folded, non-constant tree into a tape.
pub(crate) fn compile(root: &Node) -> Result<Tape, TooManyRegisters> {
    let mut b = Builder::default();
    let result = b.emit(root) as usize;
    let m = allocate(&b.code, &[result])?;
    Ok(Tape {
        instrs: m.instrs,
        result: m.results[0],
        regs: m.regs,
    })
}

/// Several tapes run as one, each result kept in its own register.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct MultiTape {
    instrs: Box<[Instr]>,
    results: Box<[u8]>,
    regs: usize,
}

/// `tapes` as one tape: each is read back into SSA form (a register names
/// the value last written to it) and identical instructions are shared by
/// value numbering, so `clamp(0, rho/15, 1)` and `1 - clamp(0, rho/15, 1)`
/// compute the clamp once. Every result is the same operation on the same
/// operands as in its own tape, hence bit for bit the same value.
pub(crate) fn fuse(tapes: &[&Tape]) -> Result<MultiTape, TooManyRegisters> {
    let mut b = Builder::default();
    let mut results = Vec::with_capacity(tapes.len());
    for t in tapes {
        let mut value = [0u32; MAX_REGS];
        for ins in t.instrs.iter() {
            let args = if ins.op == Op::Var {
                [u32::from(ins.a), 0, 0]
            } else {
                let operand = |k: usize, r: u8| {
                    if k < ins.op.arity() {
                        value[r as usize]
                    } else {
                        0
                    }
                };
                [operand(0, ins.a), operand(1, ins.b), operand(2, ins.c)]
            };
            value[ins.out as usize] = b.push_as_is(ins.op, args, ins.imm);
        }
        results.push(value[t.result as usize] as usize);
    }
    allocate(&b.code, &results)
}

impl MultiTape {
    /// Instructions (to compare with the tapes it fused).
    pub(crate) fn len(&self) -> usize {
        self.instrs.len()
    }

    /// Every result, in the order of the fused tapes, into `out`.
    #[inline]
    pub(crate) fn eval_into(&self, slots: &[f64], out: &mut [f64]) {
        match self.regs {
            0..=8 => run_many::<8>(&self.instrs, &self.results, slots, out),
            9..=32 => run_many::<32>(&self.instrs, &self.results, slots, out),
            _ => run_many::<MAX_REGS>(&self.instrs, &self.results, slots, out),
        }
    }
}

/// Register allocation of SSA `code` whose values `results` are read after
/// the last instruction.
fn allocate(code: &[Ssa], results: &[usize]) -> Result<MultiTape, TooManyRegisters> {
    // Last instruction index reading each value (results live to the end).
    const NEVER: usize = usize::MAX - 1;
    let mut last_use = vec![NEVER; code.len()];
    for (i, s) in code.iter().enumerate() {
        for &arg in &s.args[..s.op.arity()] {
            last_use[arg as usize] = i;
        }
    }
    for &r in results {
        last_use[r] = usize::MAX;
    }

    let mut reg = vec![0u8; code.len()];
    let mut free: Vec<u8> = Vec::new();
    let mut regs = 0usize;
    let mut instrs = Vec::with_capacity(code.len());
    for (i, s) in code.iter().enumerate() {
        let args = &s.args[..s.op.arity()];
        for (k, &arg) in args.iter().enumerate() {
            if last_use[arg as usize] == i && !args[..k].contains(&arg) {
                free.push(reg[arg as usize]);
            }
        }
        let out = match free.pop() {
            Some(r) => r,
            None => {
                if regs == MAX_REGS {
                    return Err(TooManyRegisters);
                }
                regs += 1;
                (regs - 1) as u8
            }
        };
        reg[i] = out;
        let operand = |k: usize| args.get(k).map_or(0, |&v| reg[v as usize]);
        instrs.push(Instr {
            op: s.op,
            out,
            a: if s.op == Op::Var {
                s.args[0] as u8
            } else {
                operand(0)
            },
            b: operand(1),
            c: operand(2),
            imm: s.imm,
        });
        if last_use[i] == NEVER {
            free.push(out);
        }
    }
    Ok(MultiTape {
        instrs: instrs.into_boxed_slice(),
        results: results.iter().map(|&r| reg[r]).collect(),
        regs,
    })
}

impl Tape {
    /// Scalar evaluation; dispatches on the register-file size.
    #[inline]
    pub(crate) fn eval(&self, slots: &[f64]) -> f64 {
        match self.regs {
            0..=8 => run::<8>(&self.instrs, self.result, slots),
            9..=32 => run::<32>(&self.instrs, self.result, slots),
            _ => run::<MAX_REGS>(&self.instrs, self.result, slots),
        }
    }

    /// Interval evaluation; dispatches on the register-file size.
    pub(crate) fn eval_interval(&self, slots: &[Interval]) -> Interval {
        match self.regs {
            0..=8 => run_interval::<8>(&self.instrs, self.result, slots),
            9..=32 => run_interval::<32>(&self.instrs, self.result, slots),
            _ => run_interval::<MAX_REGS>(&self.instrs, self.result, slots),
        }
    }
}

/// The tape loop: runs `code` over a register file of `N` entries of `T`
/// (set to `empty` first), each op through `apply`, and hands it back.
/// `N` is a power of two, so `% N` is a mask that keeps every index in
/// range without a bounds check. The scalar and interval evaluations are
/// this loop with `Op::apply` and `Op::apply_interval`; both are
/// monomorphised and inlined, so the scalar hot loop stays a direct match.
#[inline(always)]
fn registers<T: Copy, const N: usize>(
    code: &[Instr],
    slots: &[T],
    empty: T,
    apply: impl Fn(Op, T, T, T, f64) -> T,
) -> [T; N] {
    let mut r = [empty; N];
    for ins in code {
        let v = match ins.op {
            Op::Var => slots[ins.a as usize],
            op => apply(
                op,
                r[ins.a as usize % N],
                r[ins.b as usize % N],
                r[ins.c as usize % N],
                ins.imm,
            ),
        };
        r[ins.out as usize % N] = v;
    }
    r
}

/// A tape's value.
#[inline]
fn run<const N: usize>(code: &[Instr], result: u8, slots: &[f64]) -> f64 {
    registers::<f64, N>(code, slots, 0.0, Op::apply)[result as usize % N]
}

/// A fused tape's values.
#[inline]
fn run_many<const N: usize>(code: &[Instr], results: &[u8], slots: &[f64], out: &mut [f64]) {
    let r = registers::<f64, N>(code, slots, 0.0, Op::apply);
    for (o, &res) in out.iter_mut().zip(results) {
        *o = r[res as usize % N];
    }
}

/// The interval loop: same tape, [`Interval`] registers.
fn run_interval<const N: usize>(code: &[Instr], result: u8, slots: &[Interval]) -> Interval {
    registers::<Interval, N>(code, slots, Interval::EVERYTHING, Op::apply_interval)
        [result as usize % N]
}

impl fmt::Display for Instr {
    /// Assembly-like listing, e.g. `r1 = div_rc r0, 15`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = self.op.name();
        match (self.op, self.op.arity()) {
            (Op::Var, _) => write!(f, "r{} = var {}", self.out, self.a),
            (Op::Const, _) => write!(f, "r{} = const {}", self.out, self.imm),
            (_, 1)
                if matches!(
                    self.op,
                    Op::AddC
                        | Op::SubCR
                        | Op::MulC
                        | Op::DivRC
                        | Op::DivCR
                        | Op::MinC
                        | Op::MaxC
                        | Op::PowC
                        | Op::ClampLoC
                        | Op::ClampHiC
                ) =>
            {
                write!(f, "r{} = {name} r{}, {}", self.out, self.a, self.imm)
            }
            (_, 1) => write!(f, "r{} = {name} r{}", self.out, self.a),
            (_, 2) => write!(f, "r{} = {name} r{}, r{}", self.out, self.a, self.b),
            _ => write!(
                f,
                "r{} = {name} r{}, r{}, r{}",
                self.out, self.a, self.b, self.c
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn var(i: u8) -> Node {
        Node::Var(i)
    }

    #[test]
    fn instr_is_compact() {
        assert_eq!(std::mem::size_of::<Instr>(), 16);
    }

    #[test]
    fn constant_forms_and_cse() {
        // x/15 + 0.5
        let n = Node::binary(
            Op::Add,
            Node::binary(Op::Div, var(0), Node::Num(15.0)),
            Node::Num(0.5),
        );
        let t = compile(&n).unwrap();
        let ops: Vec<Op> = t.instrs.iter().map(|i| i.op).collect();
        assert_eq!(ops, [Op::Var, Op::DivRC, Op::AddC]);
        assert_eq!(t.regs, 1);
        assert_eq!(t.eval(&[3.0]), 3.0 / 15.0 + 0.5);
        // x / 4 becomes x * 0.25 (exact); sin(x) * sin(x) becomes square(sin(x)).
        let n = Node::binary(Op::Div, var(0), Node::Num(4.0));
        assert_eq!(compile(&n).unwrap().instrs[1].op, Op::MulC);
        let s = Node::unary(Op::Sin, var(0));
        let t = compile(&Node::binary(Op::Mul, s.clone(), s)).unwrap();
        let ops: Vec<Op> = t.instrs.iter().map(|i| i.op).collect();
        assert_eq!(ops, [Op::Var, Op::Sin, Op::Square]);
    }

    #[test]
    fn register_reuse() {
        // a + (b + (c + ...)) over 150 levels stays within a few registers.
        let mut n = var(0);
        for i in 0..150 {
            n = Node::binary(Op::Add, Node::unary(Op::Sin, var((i % 3) as u8)), n);
        }
        let t = compile(&n).unwrap();
        assert!(t.regs <= 4, "{} registers", t.regs);
        let slots = [0.1f64, 0.2, 0.3];
        let mut want = 0.1f64;
        for i in 0..150 {
            want += slots[i % 3].sin();
        }
        assert!((t.eval(&slots) - want).abs() < 1e-9);
    }

    #[test]
    fn exact_reciprocals() {
        assert_eq!(exact_reciprocal(4.0), Some(0.25));
        assert_eq!(exact_reciprocal(-0.5), Some(-2.0));
        assert_eq!(exact_reciprocal(3.0), None);
        assert_eq!(exact_reciprocal(0.0), None);
        assert_eq!(exact_reciprocal(f64::MAX), None);
    }
}
