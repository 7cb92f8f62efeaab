//! Rounding `f64` bounds to `f32` in the safe direction: indexes store
//! single-precision boxes and distance bounds to halve their memory, and a
//! stored lower bound must stay at or below the true value (an upper bound
//! at or above it), or a query would skip what it must visit.

/// Largest `f32` not above `x` (keeps a stored lower bound a lower bound).
#[inline]
pub(crate) fn f32_down(x: f64) -> f32 {
    let f = x as f32;
    if f as f64 > x { f.next_down() } else { f }
}

/// Smallest `f32` not below `x` (keeps a stored upper bound an upper bound).
#[inline]
pub(crate) fn f32_up(x: f64) -> f32 {
    let f = x as f32;
    if (f as f64) < x { f.next_up() } else { f }
}
