//! Files of millions of similar records (OBJ and 3MF vertex and triangle
//! lines, binary STL triangles), formatted on every core: blocks of
//! [`BLOCK`] items become bytes in parallel, in batches that bound the
//! memory held, and are written in order, so the bytes are those of one
//! loop over the items.

use std::io::{self, Write};

use rayon::prelude::*;

/// Items formatted per parallel task.
const BLOCK: usize = 1 << 15;
/// Most blocks formatted per batch before they are written (sixteen hold
/// about 25 MB of text per file being written; several files are written
/// at once).
const MAX_BLOCKS_PER_BATCH: usize = 16;

/// Formats `items` with `line` in parallel blocks and writes the bytes in
/// order (the same bytes as one loop over the items). A batch is two
/// blocks a thread, and its buffers serve every batch: memory touched for
/// the first time costs a page fault and the kernel's zeroing per page.
pub fn write_blocks<T: Sync>(
    items: &[T],
    m: &mut impl Write,
    line: impl Fn(&mut Vec<u8>, &T) + Sync,
) -> io::Result<()> {
    let per_batch = (2 * rayon::current_num_threads()).clamp(2, MAX_BLOCKS_PER_BATCH);
    let mut texts: Vec<Vec<u8>> = Vec::new();
    for batch in items.chunks(BLOCK * per_batch) {
        let n = batch.len().div_ceil(BLOCK);
        if texts.len() < n {
            texts.resize_with(n, Vec::new);
        }
        texts[..n]
            .par_iter_mut()
            .zip(batch.par_chunks(BLOCK))
            .for_each(|(out, block)| {
                out.clear();
                out.reserve(block.len() * 64);
                for it in block {
                    line(out, it);
                }
            });
        for t in &texts[..n] {
            m.write_all(t)?;
        }
    }
    Ok(())
}

/// Appends `glue[0] a glue[1] b glue[2] c glue[3]`: one vertex or
/// triangle line of any of the text formats.
#[inline(always)]
pub fn push_line(out: &mut Vec<u8>, glue: [&[u8]; 4], [a, b, c]: [&str; 3]) {
    out.extend_from_slice(glue[0]);
    out.extend_from_slice(a.as_bytes());
    out.extend_from_slice(glue[1]);
    out.extend_from_slice(b.as_bytes());
    out.extend_from_slice(glue[2]);
    out.extend_from_slice(c.as_bytes());
    out.extend_from_slice(glue[3]);
}

/// Three floats as shortest round-trip text (ryu).
pub struct Floats([ryu::Buffer; 3]);

impl Floats {
    /// Buffers for [`Floats::format`].
    #[inline(always)]
    pub fn new() -> Self {
        Floats([ryu::Buffer::new(), ryu::Buffer::new(), ryu::Buffer::new()])
    }

    /// The three values' text.
    #[inline(always)]
    pub fn format(&mut self, v: [f32; 3]) -> [&str; 3] {
        let [a, b, c] = &mut self.0;
        [a.format(v[0]), b.format(v[1]), c.format(v[2])]
    }
}

/// Three integers as text (itoa).
pub struct Ints([itoa::Buffer; 3]);

impl Ints {
    /// Buffers for [`Ints::format`].
    #[inline(always)]
    pub fn new() -> Self {
        Ints([
            itoa::Buffer::new(),
            itoa::Buffer::new(),
            itoa::Buffer::new(),
        ])
    }

    /// The three values' text.
    #[inline(always)]
    pub fn format(&mut self, v: [u64; 3]) -> [&str; 3] {
        let [a, b, c] = &mut self.0;
        [a.format(v[0]), b.format(v[1]), c.format(v[2])]
    }
}
