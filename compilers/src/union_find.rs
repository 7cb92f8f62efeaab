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

/// Join the sets of `a` and `b`.
pub fn join(parent: &mut [u32], a: u32, b: u32) {
    let (a, b) = (find(parent, a), find(parent, b));
    if a != b {
        parent[a.max(b) as usize] = a.min(b);
    }
}
