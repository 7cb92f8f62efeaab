//! Text files of millions of similar lines (OBJ and 3MF vertices and
//! triangles), formatted on every core: blocks of [`BLOCK`] items become
//! text in parallel, in batches that bound the memory held, and are written
//! in order, so the bytes are those of one loop over the items.

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
