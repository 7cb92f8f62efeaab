//! Rhai's functions that allocate by count (`pad`, `blob`), checked against
//! the script's heap budget before they allocate.
//!
//! The budget (`crate::heap`) is checked between operations, so it stops a
//! value that grows step by step; one call such as `a.pad(100000000000, 0)`
//! asks for its memory inside a single operation, and a failed allocation
//! aborts the process. These replacements compute the size first and fail
//! with the numbers instead; otherwise they do what Rhai's own do (pad to at
//! least `len` elements, characters or bytes; a length not above the
//! current one changes nothing).

use rhai::{Array, Blob, Dynamic, Engine, INT, ImmutableString, NativeCallContext as Ctx};

use super::values::{RResult, fail};
use crate::heap::human_bytes;

/// Bytes of one array element (`Dynamic`).
const ELEMENT: u64 = std::mem::size_of::<Dynamic>() as u64;

/// Registers the checked functions; `budget` is the script's heap budget.
pub fn register(engine: &mut Engine, budget: u64) {
    let check = move |c: &Ctx, what: &str, count: u64, each: u64| -> RResult<()> {
        let bytes = count.saturating_mul(each);
        if bytes > budget {
            return fail(
                c.call_position(),
                format!(
                    "{what}: {count} would need {}, more than the script's memory budget of {}",
                    human_bytes(bytes),
                    human_bytes(budget)
                ),
            );
        }
        Ok(())
    };
    engine.register_fn(
        "pad",
        move |c: Ctx, a: &mut Array, len: INT, item: Dynamic| -> RResult<()> {
            let len = usize::try_from(len).unwrap_or(0);
            if len > a.len() {
                check(&c, "pad", len as u64, ELEMENT)?;
                a.resize(len, item);
            }
            Ok(())
        },
    );
    // Rhai's string pads: append the fill's characters, cycling, until the
    // string has `len` characters.
    let pad_string = move |c: &Ctx, s: &mut ImmutableString, len: INT, fill: &str| {
        let len = usize::try_from(len).unwrap_or(0);
        let have = s.chars().count();
        if len > have && !fill.is_empty() {
            let widest = fill.chars().map(char::len_utf8).max().unwrap_or(1);
            check(c, "pad", len as u64, widest as u64)?;
            let mut out = s.to_string();
            out.extend(fill.chars().cycle().take(len - have));
            *s = out.into();
        }
        Ok(())
    };
    engine.register_fn(
        "pad",
        move |c: Ctx, s: &mut ImmutableString, len: INT, ch: char| -> RResult<()> {
            pad_string(&c, s, len, ch.encode_utf8(&mut [0; 4]))
        },
    );
    engine.register_fn(
        "pad",
        move |c: Ctx, s: &mut ImmutableString, len: INT, fill: ImmutableString| -> RResult<()> {
            pad_string(&c, s, len, &fill)
        },
    );
    engine.register_fn(
        "pad",
        move |c: Ctx, b: &mut Blob, len: INT, value: INT| -> RResult<()> {
            let len = usize::try_from(len).unwrap_or(0);
            if len > b.len() {
                check(&c, "pad", len as u64, 1)?;
                b.resize(len, value as u8);
            }
            Ok(())
        },
    );
    engine.register_fn("blob", move |c: Ctx, len: INT| -> RResult<Blob> {
        let len = usize::try_from(len).unwrap_or(0);
        check(&c, "blob", len as u64, 1)?;
        Ok(vec![0; len])
    });
    engine.register_fn(
        "blob",
        move |c: Ctx, len: INT, value: INT| -> RResult<Blob> {
            let len = usize::try_from(len).unwrap_or(0);
            check(&c, "blob", len as u64, 1)?;
            Ok(vec![value as u8; len])
        },
    );
}
