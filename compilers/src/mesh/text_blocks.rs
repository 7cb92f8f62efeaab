//! Files of millions of similar records (OBJ and 3MF vertex and triangle
//! lines, binary STL triangles), formatted on every core: blocks of
//! [`BLOCK`] items become bytes in parallel, in batches that bound the
//! memory held, and are written in order, so the bytes are those of one
//! loop over the items.

use std::io::{self, Write};

use rayon::prelude::*;

/// Items formatted per parallel task.
const BLOCK: usize = 1 << 15;
/// Blocks formatted per batch before they are written: about 25 MB of text
/// held per file being written (several files are written at once).
const BLOCKS_PER_BATCH: usize = 16;

/// Formats `items` with `line` in parallel blocks and writes the text in
/// order (the same bytes as one loop over the items).
pub fn write_blocks<T: Sync>(
    items: &[T],
    m: &mut impl Write,
    line: impl Fn(&mut Vec<u8>, &T) + Sync,
) -> io::Result<()> {
    for batch in items.chunks(BLOCK * BLOCKS_PER_BATCH) {
        let texts: Vec<Vec<u8>> = batch
            .par_chunks(BLOCK)
            .map(|block| {
                let mut out = Vec::with_capacity(block.len() * 64);
                for it in block {
                    line(&mut out, it);
                }
                out
            })
            .collect();
        for t in &texts {
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
