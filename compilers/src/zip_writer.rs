//! The ZIP container of our 3MF packages (APPNOTE.TXT 6.3.10, PKWARE):
//! deflated entries compressed by [`crate::par_deflate`], fixed time stamps
//! (1980-01-01 00:00) so the bytes repeat run to run, and Zip64 records for
//! an entry declared large or wherever an offset or a count no longer fits
//! 32 bits.
//!
//! The zip crate cannot take data deflated elsewhere: an entry is
//! compressed on the thread that writes it. This writer is small because
//! it does only what the packages need (no encryption, no streaming
//! without `Seek`, names in ASCII or UTF-8); archives are read back by the
//! zip crate and Python's `zipfile` in the tests.

use std::io::{self, Seek, SeekFrom, Write};

use crate::par_deflate::{Deflated, ParDeflate};

/// Deflate level of every entry (fast: mesh XML compresses well anyway).
const LEVEL: u32 = 1;
/// 1980-01-01 in MS-DOS date format; the time is 00:00.
const DOS_DATE: u16 = (1 << 5) | 1;
/// Largest value of a 32-bit field (larger ones go to Zip64 records).
const MAX32: u64 = 0xFFFF_FFFF;

/// One written entry, for the central directory.
struct Entry {
    name: String,
    offset: u64,
    d: Deflated,
    /// The local header carries a Zip64 extra field.
    zip64: bool,
    /// 8 = deflate, 0 = stored.
    method: u16,
}

/// A ZIP archive being written to `w`.
pub struct ZipOut<W: Write + Seek> {
    w: W,
    entries: Vec<Entry>,
}

impl<W: Write + Seek> ZipOut<W> {
    /// An empty archive at `w`'s current position.
    pub fn new(w: W) -> Self {
        Self {
            w,
            entries: Vec::new(),
        }
    }

    /// Adds entry `name` with the bytes `fill` writes, deflated on every
    /// core. `large` must be true when the entry may reach 4 GiB (its
    /// local header then has room for 64-bit sizes); otherwise an entry that
    /// does is an error.
    pub fn entry(
        &mut self,
        name: &str,
        large: bool,
        fill: impl FnOnce(&mut ParDeflate<&mut W>) -> io::Result<()>,
    ) -> io::Result<()> {
        let offset = self.w.stream_position()?;
        let extra: u16 = if large { 20 } else { 0 };
        let mut h = Vec::with_capacity(30 + name.len() + extra as usize);
        put32(&mut h, 0x0403_4b50);
        put16(&mut h, if large { 45 } else { 20 }); // version needed
        put16(&mut h, general_flags(name));
        put16(&mut h, 8); // deflate
        put16(&mut h, 0); // time
        put16(&mut h, DOS_DATE);
        put32(&mut h, 0); // crc, sizes: filled in below
        put32(&mut h, 0);
        put32(&mut h, 0);
        put16(&mut h, name.len() as u16);
        put16(&mut h, extra);
        h.extend_from_slice(name.as_bytes());
        if large {
            put16(&mut h, 1); // Zip64 extended information
            put16(&mut h, 16);
            put64(&mut h, 0);
            put64(&mut h, 0);
        }
        self.w.write_all(&h)?;
        let mut z = ParDeflate::new(&mut self.w, LEVEL);
        fill(&mut z)?;
        let (_, d) = z.finish()?;
        if !large && (d.raw > MAX32 || d.compressed > MAX32) {
            return Err(io::Error::other(format!(
                "{name}: {} bytes need a Zip64 entry (declare it large)",
                d.raw
            )));
        }
        let end = self.w.stream_position()?;
        let mut fix = Vec::with_capacity(12);
        put32(&mut fix, d.crc);
        if large {
            put32(&mut fix, MAX32 as u32);
            put32(&mut fix, MAX32 as u32);
        } else {
            put32(&mut fix, d.compressed as u32);
            put32(&mut fix, d.raw as u32);
        }
        self.w.seek(SeekFrom::Start(offset + 14))?;
        self.w.write_all(&fix)?;
        if large {
            let mut sizes = Vec::with_capacity(16);
            put64(&mut sizes, d.raw);
            put64(&mut sizes, d.compressed);
            self.w
                .seek(SeekFrom::Start(offset + 30 + name.len() as u64 + 4))?;
            self.w.write_all(&sizes)?;
        }
        self.w.seek(SeekFrom::Start(end))?;
        self.entries.push(Entry {
            name: name.to_owned(),
            offset,
            d,
            zip64: large,
            method: 8,
        });
        Ok(())
    }

    /// Adds entry `name` holding `bytes` as they are (method 0, "stored"):
    /// for data compressed already, such as PNG images, which deflate
    /// would only slow down. Entries of 4 GiB or more are refused.
    pub fn stored(&mut self, name: &str, bytes: &[u8]) -> io::Result<()> {
        let size = u32::try_from(bytes.len())
            .ok()
            .filter(|s| u64::from(*s) < MAX32)
            .ok_or_else(|| io::Error::other(format!("{name}: 4 GiB or more in one entry")))?;
        let offset = self.w.stream_position()?;
        let mut crc = crc32fast::Hasher::new();
        crc.update(bytes);
        let crc = crc.finalize();
        let mut h = Vec::with_capacity(30 + name.len());
        put32(&mut h, 0x0403_4b50);
        put16(&mut h, 20);
        put16(&mut h, general_flags(name));
        put16(&mut h, 0); // stored
        put16(&mut h, 0);
        put16(&mut h, DOS_DATE);
        put32(&mut h, crc);
        put32(&mut h, size);
        put32(&mut h, size);
        put16(&mut h, name.len() as u16);
        put16(&mut h, 0);
        h.extend_from_slice(name.as_bytes());
        self.w.write_all(&h)?;
        self.w.write_all(bytes)?;
        self.entries.push(Entry {
            name: name.to_owned(),
            offset,
            d: Deflated {
                crc,
                raw: u64::from(size),
                compressed: u64::from(size),
            },
            zip64: false,
            method: 0,
        });
        Ok(())
    }

    /// Writes the central directory and the end records; returns `w`.
    pub fn finish(mut self) -> io::Result<W> {
        let cd_start = self.w.stream_position()?;
        let mut cd = Vec::new();
        for e in &self.entries {
            // Zip64 fields for what does not fit, in the order APPNOTE gives.
            let mut z64 = Vec::new();
            let big_sizes = e.zip64 || e.d.raw > MAX32 || e.d.compressed > MAX32;
            if big_sizes {
                put64(&mut z64, e.d.raw);
                put64(&mut z64, e.d.compressed);
            }
            if e.offset >= MAX32 {
                put64(&mut z64, e.offset);
            }
            let needs64 = !z64.is_empty();
            put32(&mut cd, 0x0201_4b50);
            put16(&mut cd, (3 << 8) | 45); // made by: Unix, 4.5
            put16(&mut cd, if needs64 { 45 } else { 20 });
            put16(&mut cd, general_flags(&e.name));
            put16(&mut cd, e.method);
            put16(&mut cd, 0);
            put16(&mut cd, DOS_DATE);
            put32(&mut cd, e.d.crc);
            put32(
                &mut cd,
                if big_sizes { MAX32 } else { e.d.compressed } as u32,
            );
            put32(&mut cd, if big_sizes { MAX32 } else { e.d.raw } as u32);
            put16(&mut cd, e.name.len() as u16);
            put16(&mut cd, if needs64 { 4 + z64.len() as u16 } else { 0 });
            put16(&mut cd, 0); // comment
            put16(&mut cd, 0); // disk
            put16(&mut cd, 0); // internal attributes
            put32(&mut cd, 0o100644 << 16); // regular file, rw-r--r--
            put32(&mut cd, e.offset.min(MAX32) as u32);
            cd.extend_from_slice(e.name.as_bytes());
            if needs64 {
                put16(&mut cd, 1);
                put16(&mut cd, z64.len() as u16);
                cd.extend_from_slice(&z64);
            }
        }
        self.w.write_all(&cd)?;
        let cd_end = cd_start + cd.len() as u64;
        let n = self.entries.len() as u64;
        let mut tail = Vec::new();
        if cd_end >= MAX32 || n >= 0xFFFF {
            // Zip64 end of central directory record and its locator.
            put32(&mut tail, 0x0606_4b50);
            put64(&mut tail, 44);
            put16(&mut tail, (3 << 8) | 45);
            put16(&mut tail, 45);
            put32(&mut tail, 0);
            put32(&mut tail, 0);
            put64(&mut tail, n);
            put64(&mut tail, n);
            put64(&mut tail, cd.len() as u64);
            put64(&mut tail, cd_start);
            put32(&mut tail, 0x0706_4b50);
            put32(&mut tail, 0);
            put64(&mut tail, cd_end);
            put32(&mut tail, 1);
        }
        put32(&mut tail, 0x0605_4b50);
        put16(&mut tail, 0);
        put16(&mut tail, 0);
        put16(&mut tail, n.min(0xFFFF) as u16);
        put16(&mut tail, n.min(0xFFFF) as u16);
        put32(&mut tail, (cd.len() as u64).min(MAX32) as u32);
        put32(&mut tail, cd_start.min(MAX32) as u32);
        put16(&mut tail, 0); // comment
        self.w.write_all(&tail)?;
        self.w.flush()?;
        Ok(self.w)
    }
}

/// Bit 11 (names in UTF-8) when the name is not plain ASCII.
fn general_flags(name: &str) -> u16 {
    if name.is_ascii() { 0 } else { 1 << 11 }
}

fn put16(v: &mut Vec<u8>, x: u16) {
    v.extend_from_slice(&x.to_le_bytes());
}

fn put32(v: &mut Vec<u8>, x: u32) {
    v.extend_from_slice(&x.to_le_bytes());
}

fn put64(v: &mut Vec<u8>, x: u64) {
    v.extend_from_slice(&x.to_le_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::{Cursor, Read};

    fn archive(large: bool) -> Vec<u8> {
        let mut z = ZipOut::new(Cursor::new(Vec::new()));
        z.entry("a.txt", false, |w| w.write_all(b"hello")).unwrap();
        z.entry("dir/é.xml", large, |w| {
            for i in 0..200_000 {
                writeln!(w, "<v i=\"{i}\"/>")?;
            }
            Ok(())
        })
        .unwrap();
        z.entry("empty", false, |_| Ok(())).unwrap();
        z.stored("kept.bin", &[7; 1000]).unwrap();
        z.finish().unwrap().into_inner()
    }

    #[test]
    fn the_zip_crate_reads_it_back() {
        for large in [false, true] {
            let bytes = archive(large);
            assert_eq!(bytes, archive(large), "deterministic");
            let mut z = zip::ZipArchive::new(Cursor::new(bytes)).unwrap();
            let names: Vec<String> = z.file_names().map(String::from).collect();
            assert_eq!(names.len(), 4);
            let mut kept = Vec::new();
            let mut f = z.by_name("kept.bin").unwrap();
            assert_eq!(f.compression(), zip::CompressionMethod::Stored);
            f.read_to_end(&mut kept).unwrap();
            assert_eq!(kept, vec![7; 1000]);
            drop(f);
            let mut s = String::new();
            z.by_name("a.txt").unwrap().read_to_string(&mut s).unwrap();
            assert_eq!(s, "hello");
            let mut f = z.by_name("dir/é.xml").unwrap();
            assert_eq!(f.compression(), zip::CompressionMethod::Deflated);
            let mut s = String::new();
            f.read_to_string(&mut s).unwrap(); // checks the CRC
            assert_eq!(s.lines().count(), 200_000);
            assert!(s.ends_with("<v i=\"199999\"/>\n"));
            drop(f);
            let mut s = String::new();
            z.by_name("empty").unwrap().read_to_string(&mut s).unwrap();
            assert!(s.is_empty());
        }
    }

    #[test]
    fn python_zipfile_tests_it() {
        // Python's zipfile is an independent reader (CRC, sizes, Zip64
        // extra fields); skipped where there is no python3.
        let Ok(dir) = tempfile::tempdir() else { return };
        for large in [false, true] {
            let path = dir.path().join(format!("t{large}.zip"));
            std::fs::write(&path, archive(large)).unwrap();
            let out = std::process::Command::new("python3")
                .arg("-c")
                .arg("import sys, zipfile; z = zipfile.ZipFile(sys.argv[1]); assert z.testzip() is None; print(sorted(i.file_size for i in z.infolist()))")
                .arg(&path)
                .output();
            let Ok(out) = out else { return };
            assert!(
                out.status.success(),
                "{}",
                String::from_utf8_lossy(&out.stderr)
            );
            assert_eq!(
                String::from_utf8_lossy(&out.stdout).trim(),
                "[0, 5, 1000, 3088890]"
            );
        }
    }
}
