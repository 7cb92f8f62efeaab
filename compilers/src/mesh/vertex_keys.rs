//! Triangles before their vertices are shared, and the vertex keys that
//! share them: every contour point has a 64-bit key naming the grid edge,
//! face or tet it lies on, so neighbouring cubes (and segments) that compute
//! the same point give it the same key. A contouring task deduplicates its
//! band's vertices by key ([`BandMesh`]; the one-label path builds it
//! directly, see `one_label`); the contourer then gives each new key its
//! index in its label's mesh ([`KeyMap`]).

use std::collections::HashMap;
use std::hash::{BuildHasherDefault, Hasher};

/// Hasher for the vertex keys (already well spread u64s): one multiply
/// (Fibonacci hashing) instead of SipHash, which dominated the merge.
/// Other keys (flat-region keys, outline indices) go through `write`, FNV-1a
/// over their bytes. No map of the contourer is iterated, so the hasher
/// changes no output; SipHash's resistance to chosen keys buys nothing for
/// keys that come from our own grid.
#[derive(Default)]
pub(super) struct KeyHasher(u64);

impl Hasher for KeyHasher {
    fn finish(&self) -> u64 {
        self.0
    }

    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 = (self.0 ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3);
        }
    }

    fn write_u64(&mut self, k: u64) {
        // Mixed into the state (not replacing it), so a key's earlier parts
        // count: `(label, key)` pairs of two labels and one key land apart.
        // A lone u64 hashes as before (the state starts at 0).
        self.0 = (self.0 ^ k)
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .rotate_left(26);
    }
}

pub(super) type KeyMap = HashMap<u64, u32, BuildHasherDefault<KeyHasher>>;

/// A map hashed with [`KeyHasher`]: the contourer's maps, looked up once
/// a flat cube or an outline edge (SipHash on the 16-byte flat-region key
/// is far slower, and the keys are not attacker-chosen).
pub(super) type FastMap<K, V> = HashMap<K, V, BuildHasherDefault<KeyHasher>>;

/// A vertex: its key (shared across cubes) and position.
#[derive(Clone, Copy, Debug)]
pub(super) struct VRef {
    pub key: u64,
    pub pos: [f32; 3],
}

/// A triangle for one label, before vertex sharing.
#[derive(Clone, Copy, Debug)]
pub(super) struct Tri {
    pub label: u16,
    pub v: [VRef; 3],
}

/// One band's triangles over its own vertex list, deduplicated per label
/// (first appearance order, so the merged meshes list vertices in the same
/// order as a triangle-by-triangle merge would).
pub(super) struct BandMesh {
    /// Label, key and position of each distinct (label, key).
    pub verts: Vec<(u16, u64, [f32; 3])>,
    /// Label and row-local vertex indices.
    pub tris: Vec<(u16, [u32; 3])>,
}

impl BandMesh {
    pub fn new(tris: Vec<Tri>) -> BandMesh {
        let mut local: FastMap<(u16, u64), u32> =
            FastMap::with_capacity_and_hasher(tris.len(), Default::default());
        let mut verts = Vec::with_capacity(tris.len());
        let tris = tris
            .iter()
            .map(|t| {
                let idx = t.v.map(|v| {
                    *local.entry((t.label, v.key)).or_insert_with(|| {
                        verts.push((t.label, v.key, v.pos));
                        (verts.len() - 1) as u32
                    })
                });
                (t.label, idx)
            })
            .collect();
        BandMesh { verts, tris }
    }
}

#[cfg(test)]
mod tests {
    use std::hash::BuildHasher;

    use super::*;

    #[test]
    fn every_part_of_a_key_counts_in_its_hash() {
        let h = BuildHasherDefault::<KeyHasher>::default();
        let key = 0x0123_4567_89ab_cdef_u64;
        // A lone vertex key hashes as Fibonacci hashing of the key.
        assert_eq!(
            h.hash_one(key),
            key.wrapping_mul(0x9E37_79B9_7F4A_7C15).rotate_left(26)
        );
        // The label of a (label, key) pair is not dropped by the key.
        assert_ne!(h.hash_one((1u16, key)), h.hash_one((2u16, key)));
        // Flat-region keys and outline edges go through the bytes.
        assert_ne!(h.hash_one([3usize, 4]), h.hash_one([4usize, 3]));
    }
}
