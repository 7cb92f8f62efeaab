//! Deflate on every core, with bytes that do not depend on the thread
//! count: pigz's method (Mark Adler, "pigz: a parallel implementation of
//! gzip", 2007).
//!
//! The input is cut into pieces of [`CHUNK`] bytes at fixed offsets. Each
//! piece is compressed on its own, primed with the 32 KiB of input before it
//! as the dictionary (so matches reach back across the cut, as in one
//! stream), and ends with a sync flush: an empty stored block that leaves
//! the output on a byte boundary. The pieces concatenated are one valid raw
//! deflate stream (RFC 1951); the last piece ends with the final block. The
//! CRC-32 of the input is computed piece by piece and combined.
//!
//! Why: the zip crate deflates an entry on the calling thread. A mesh
//! export's 3MF holds hundreds of megabytes of XML for a curved design, and
//! deflating it on one core made it the slowest file of the export.

use std::io::{self, Write};

use flate2::{Compress, Compression, FlushCompress, Status};
use rayon::prelude::*;

/// Input bytes per independently compressed piece.
pub const CHUNK: usize = 1 << 20;
/// Pieces compressed per batch (memory: about this many MiB of input).
const BATCH: usize = 32;
/// Deflate's window: the dictionary handed to each piece.
const WINDOW: usize = 32 << 10;

/// A writer that deflates what it is given into `out`, in parallel batches.
pub struct ParDeflate<W: Write> {
    out: W,
    level: u32,
    /// The last [`WINDOW`] bytes already compressed (the next piece's
    /// dictionary), then the input not yet compressed.
    buf: Vec<u8>,
    /// Length of the dictionary at the start of `buf`.
    dict: usize,
    crc: crc32fast::Hasher,
    total_in: u64,
    total_out: u64,
}

/// What a finished stream amounts to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Deflated {
    /// CRC-32 of the input.
    pub crc: u32,
    /// Input bytes.
    pub raw: u64,
    /// Deflated bytes written.
    pub compressed: u64,
}

impl<W: Write> ParDeflate<W> {
    /// A stream at zlib `level` (0 to 9) into `out`.
    pub fn new(out: W, level: u32) -> Self {
        Self {
            out,
            level: level.min(9),
            buf: Vec::new(),
            dict: 0,
            crc: crc32fast::Hasher::new(),
            total_in: 0,
            total_out: 0,
        }
    }

    /// Compresses the pending input's first `pieces` pieces (the last of
    /// them final when `last`) and writes them.
    fn compress(&mut self, pieces: usize, last: bool) -> io::Result<()> {
        let start = self.dict;
        let end = (start + pieces * CHUNK).min(self.buf.len());
        let level = self.level;
        let buf = &self.buf;
        let out: Vec<(Vec<u8>, crc32fast::Hasher)> = (0..pieces)
            .into_par_iter()
            .map(|k| {
                let a = start + k * CHUNK;
                let b = (a + CHUNK).min(end);
                let dict = &buf[a.saturating_sub(WINDOW)..a];
                let is_last = last && b == end;
                let mut h = crc32fast::Hasher::new();
                h.update(&buf[a..b]);
                deflate_piece(dict, &buf[a..b], level, is_last).map(|d| (d, h))
            })
            .collect::<io::Result<_>>()?;
        for (d, h) in out {
            self.out.write_all(&d)?;
            self.total_out += d.len() as u64;
            self.crc.combine(&h);
        }
        self.total_in += (end - start) as u64;
        // Keep the window before the rest as the next dictionary.
        let keep = end.saturating_sub(WINDOW);
        self.buf.drain(..keep);
        self.dict = end - keep;
        Ok(())
    }

    /// Compresses the rest and ends the stream; returns the writer and the
    /// stream's CRC and sizes.
    pub fn finish(mut self) -> io::Result<(W, Deflated)> {
        let pending = self.buf.len() - self.dict;
        self.compress(pending.div_ceil(CHUNK).max(1), true)?;
        self.out.flush()?;
        let d = Deflated {
            crc: self.crc.clone().finalize(),
            raw: self.total_in,
            compressed: self.total_out,
        };
        Ok((self.out, d))
    }
}

impl<W: Write> Write for ParDeflate<W> {
    fn write(&mut self, data: &[u8]) -> io::Result<usize> {
        self.buf.extend_from_slice(data);
        // Keep at least one piece back: only `finish` knows the last one.
        if self.buf.len() - self.dict > BATCH * CHUNK {
            self.compress(BATCH, false)?;
        }
        Ok(data.len())
    }

    /// Pending input stays pending: a piece is cut only at its fixed size,
    /// so the bytes do not depend on when callers flush.
    fn flush(&mut self) -> io::Result<()> {
        Ok(())
    }
}

/// One piece as raw deflate, primed with `dict`, ending with a sync flush
/// or, when `last`, the final block.
fn deflate_piece(dict: &[u8], data: &[u8], level: u32, last: bool) -> io::Result<Vec<u8>> {
    let mut c = Compress::new(Compression::new(level), false);
    if !dict.is_empty() {
        c.set_dictionary(dict).map_err(io::Error::other)?;
    }
    let flush = if last {
        FlushCompress::Finish
    } else {
        FlushCompress::Sync
    };
    let mut out = Vec::with_capacity(data.len() / 4 + 64);
    loop {
        let consumed = c.total_in() as usize;
        if out.capacity() - out.len() < 64 {
            out.reserve(out.capacity().max(4096));
        }
        let status = c
            .compress_vec(&data[consumed..], &mut out, flush)
            .map_err(io::Error::other)?;
        let done_in = c.total_in() as usize == data.len();
        match status {
            Status::StreamEnd => break,
            // A sync flush is complete once the input is used up and the
            // output buffer was not filled (nothing left to emit).
            Status::Ok | Status::BufError if !last && done_in && out.len() < out.capacity() => {
                break;
            }
            _ => {}
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use flate2::read::DeflateDecoder;
    use std::io::Read;

    /// Text with repeats near and far (as mesh XML has), `n` bytes.
    fn sample(n: usize) -> Vec<u8> {
        let mut s = Vec::with_capacity(n + 64);
        let mut x = 12345u64;
        while s.len() < n {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            writeln!(s, "     <vertex x=\"{}\" y=\"1.5\"/>", x % 100_000).unwrap();
        }
        s.truncate(n);
        s
    }

    fn deflate(data: &[u8], pieces_of: &[usize]) -> (Vec<u8>, Deflated) {
        let mut d = ParDeflate::new(Vec::new(), 1);
        let mut at = 0;
        for (i, &n) in pieces_of.iter().cycle().enumerate() {
            if at >= data.len() || i > 100_000 {
                break;
            }
            let b = (at + n).min(data.len());
            d.write_all(&data[at..b]).unwrap();
            at = b;
        }
        d.finish().unwrap()
    }

    #[test]
    fn round_trips_with_crc_and_sizes() {
        for n in [
            0,
            1,
            1000,
            CHUNK - 1,
            CHUNK,
            CHUNK + 1,
            3 * CHUNK + 77,
            (BATCH + 3) * CHUNK,
        ] {
            let data = sample(n);
            let (z, d) = deflate(&data, &[1 << 16]);
            let mut back = Vec::new();
            DeflateDecoder::new(&z[..]).read_to_end(&mut back).unwrap();
            assert_eq!(back, data, "n = {n}");
            assert_eq!(d.crc, crc32fast::hash(&data), "n = {n}");
            assert_eq!((d.raw, d.compressed), (n as u64, z.len() as u64));
        }
    }

    #[test]
    fn bytes_do_not_depend_on_write_sizes_or_threads() {
        let data = sample(5 * CHUNK + 12345);
        let (a, _) = deflate(&data, &[7, 100_000, 3]);
        let (b, _) = deflate(&data, &[CHUNK * 2]);
        assert_eq!(a, b);
        let one = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        let (c, _) = one.install(|| deflate(&data, &[1 << 16]));
        assert_eq!(a, c);
        // The dictionary carries matches across the cuts: close to one
        // stream's size.
        let mut whole = flate2::write::DeflateEncoder::new(Vec::new(), Compression::new(1));
        whole.write_all(&data).unwrap();
        let whole = whole.finish().unwrap();
        assert!(
            a.len() < whole.len() + whole.len() / 50,
            "{} vs {}",
            a.len(),
            whole.len()
        );
    }
}
