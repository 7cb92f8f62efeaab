//! Union–find over `u32` ids (path halving; the smaller root wins, so the
//! result does not depend on the order of the joins).

/// The root of `i`.
pub fn find(parent: &mut [u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        let up = parent[parent[i as usize] as usize];
        parent[i as usize] = up;
        i = up;
    }
    i
}

/// The root of `i`, without shortening the path (for readers that share
/// `parent`).
pub fn root(parent: &[u32], mut i: u32) -> u32 {
    while parent[i as usize] != i {
        i = parent[i as usize];
    }
    i
}

/// Join the sets of `a` and `b`.
pub fn join(parent: &mut [u32], a: u32, b: u32) {
    let (a, b) = (find(parent, a), find(parent, b));
    link(parent, a, b);
}

/// Join the sets whose roots are `a` and `b` (the smaller root wins); the
/// joined set's root.
pub fn link(parent: &mut [u32], a: u32, b: u32) -> u32 {
    let (lo, hi) = (a.min(b), a.max(b));
    parent[hi as usize] = lo;
    lo
}
