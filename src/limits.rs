//! Resource limits: the memory budget a bake must fit in before it allocates.

use crate::error::{Error, Result};

/// The most samples (texels x channels) relume decodes from one image file: 2^30, e.g. a
/// 32768² height map, 4 GiB as f32. Decoders allocate what a header declares before they read
/// the data, so a damaged header is refused against this before any decoding.
pub const MAX_IMAGE_SAMPLES: u64 = 1 << 30;

/// Refuse an image whose header declares more than [`MAX_IMAGE_SAMPLES`].
pub fn check_declared_samples(
    path: &std::path::Path,
    width: u64,
    height: u64,
    channels: u64,
) -> Result<()> {
    let samples = width.saturating_mul(height).saturating_mul(channels);
    if samples > MAX_IMAGE_SAMPLES {
        return Err(Error::input(
            path,
            format!(
                "the header declares {width}x{height} texels x {channels} channel(s), over relume's \
                 limit of 2^30 samples per image (a damaged header, or split the map into tiles)"
            ),
        ));
    }
    Ok(())
}

/// Read an OpenEXR file's headers and refuse one whose parts together declare more than
/// [`MAX_IMAGE_SAMPLES`], or that is too short to hold the chunks they declare, before the `exr`
/// crate allocates them. Returns the number of parts
/// (0 when the header is unreadable: the decoder then reports it).
pub fn check_exr_header(path: &std::path::Path) -> Result<usize> {
    let Ok(meta) = exr::meta::MetaData::read_from_file(path, false) else {
        return Ok(0);
    };
    let (mut samples, mut last) = (0u64, (0, 0, 0));
    for h in meta.headers.iter() {
        let (w, ht) = (h.layer_size.width() as u64, h.layer_size.height() as u64);
        last = (w, ht, h.channels.list.len() as u64);
        samples = samples.saturating_add(w.saturating_mul(ht).saturating_mul(last.2));
    }
    if samples > MAX_IMAGE_SAMPLES {
        return Err(Error::input(
            path,
            format!(
                "the header declares {samples} samples in {} part(s) (the last {}x{} x {} \
                 channel(s)), over relume's limit of 2^30 per image: a damaged header?",
                meta.headers.len(),
                last.0,
                last.1,
                last.2
            ),
        ));
    }
    // Every chunk the headers declare has an 8-byte offset-table entry and, in the file, at least
    // its 8-byte chunk header (scan line y or tile coordinates, and data size): a file shorter
    // than that cannot hold the image, and the decoder would fill what is missing (a 400-byte
    // "decompression bomb" took it seconds and gigabytes; found by AFL).
    let chunks: u64 = meta.headers.iter().map(|h| h.chunk_count as u64).sum();
    let need = chunks.saturating_mul(16);
    let have = std::fs::metadata(path).map_or(u64::MAX, |m| m.len());
    if have < need {
        return Err(Error::input(
            path,
            format!(
                "the header declares {chunks} chunk(s), which need at least {need} bytes, but \
                 the file has {have}: truncated or damaged"
            ),
        ));
    }
    // What the pixels decode to against what the file could hold at its compression's largest
    // expansion ([`exr_max_expansion`]): a 530-byte DWAB file declaring 134–805 M samples
    // decoded (into zeros) for 2–22 s and 1.5–10 GB (found by AFL).
    for h in meta.headers.iter() {
        use exr::compression::Compression as C;
        if matches!(h.compression, C::HTJ2K32 | C::HTJ2K256) {
            // exr 1.74 cannot decode it, after allocating a block buffer the header sizes
            // (2.1 GB and 2.9 s for a 371-byte file; found by AFL).
            return Err(Error::unsupported(
                path,
                format!(
                    "{} is not supported by the EXR decoder; re-save with ZIP or PIZ",
                    h.compression
                ),
            ));
        }
        let per_texel: u64 = h
            .channels
            .list
            .iter()
            .map(|c| c.sample_type.bytes_per_sample() as u64)
            .sum();
        // The decoder also allocates a whole block of scan lines (up to 256) however few the
        // image has: that counts as decoded bytes too.
        let raw = (h.layer_size.width() as u64)
            .saturating_mul(h.layer_size.height() as u64)
            .saturating_mul(per_texel)
            .max(h.max_block_byte_size() as u64);
        let ratio = exr_max_expansion(h.compression);
        if raw > have.saturating_mul(ratio) {
            return Err(Error::input(
                path,
                format!(
                    "the header declares {}x{} texels ({raw} bytes of samples) with {}, which \
                     expands at most {ratio}:1, but the file has {have} bytes: damaged, or a \
                     decompression bomb",
                    h.layer_size.width(),
                    h.layer_size.height(),
                    h.compression
                ),
            ));
        }
    }
    Ok(meta.headers.len())
}

/// The largest ratio of decoded sample bytes to stored bytes an OpenEXR compression can reach,
/// with margin. None: 1. RLE: a 2-byte run codes at most 128 bytes (64:1). ZIP, ZIPS: deflate's
/// limit, 1032:1; PXR24 deflates 3 of every 4 bytes of a float (1376:1). B44/B44A: a 4x4 block
/// of halves (32 bytes) in at least 3 bytes, floats stored as they are (11:1). PIZ: Huffman codes
/// of at least 1 bit with run-length codes of at most 255 repeats in at least 10 bits (~410:1
/// for 16-bit values): 4096 leaves a tenfold margin. DWAA/DWAB code a flat 8x8 block
/// in a DC value deflated at most 1032:1 (2 bytes for 64 samples of up to 4 bytes: ~132,000:1):
/// 2^18. A file over these bounds cannot hold the samples its header declares.
fn exr_max_expansion(c: exr::compression::Compression) -> u64 {
    use exr::compression::Compression as C;
    match c {
        C::Uncompressed => 1,
        C::RLE => 64,
        C::ZIP1 | C::ZIP16 => 1032,
        C::PXR24 => 1376,
        C::B44 | C::B44A => 11,
        C::PIZ => 4096,
        C::DWAA(_) | C::DWAB(_) => 1 << 18,
        // Refused before this is asked (not decodable by exr 1.74).
        C::HTJ2K32 | C::HTJ2K256 => 1,
    }
}

/// Physical memory of this machine in bytes (Linux `/proc/meminfo`; 8 GiB when unknown).
pub fn physical_memory() -> u64 {
    std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("MemTotal:"))
                .and_then(|l| l.split_whitespace().nth(1))
                .and_then(|kb| kb.parse::<u64>().ok())
        })
        .map(|kb| kb * 1024)
        .unwrap_or(8 << 30)
}

/// The default budget: 75 % of physical memory.
pub fn default_max_memory() -> u64 {
    physical_memory() / 4 * 3
}

/// Format a byte count for people (`1.5 GiB`).
pub fn human_bytes(bytes: u64) -> String {
    const UNITS: [&str; 5] = ["B", "KiB", "MiB", "GiB", "TiB"];
    let mut v = bytes as f64;
    let mut u = 0;
    while v >= 1024.0 && u + 1 < UNITS.len() {
        v /= 1024.0;
        u += 1;
    }
    if u == 0 {
        format!("{bytes} B")
    } else {
        format!("{v:.1} {}", UNITS[u])
    }
}

/// Parse a human byte count: `512M`, `2G`, `1.5GiB`, `1000000`.
pub fn parse_bytes(s: &str) -> std::result::Result<u64, String> {
    let t = s.trim();
    let split = t.find(|c: char| c.is_ascii_alphabetic()).unwrap_or(t.len());
    let (num, unit) = t.split_at(split);
    let v: f64 = num
        .trim()
        .parse()
        .map_err(|_| format!("`{s}` is not a size (try 512M, 8G)"))?;
    let mult = match unit.trim().to_ascii_lowercase().as_str() {
        "" | "b" => 1u64,
        "k" | "kb" | "kib" => 1 << 10,
        "m" | "mb" | "mib" => 1 << 20,
        "g" | "gb" | "gib" => 1 << 30,
        "t" | "tb" | "tib" => 1 << 40,
        other => {
            return Err(format!(
                "unknown unit `{other}` in `{s}` (use K, M, G or T)"
            ))
        }
    };
    if !(v.is_finite() && v >= 0.0) {
        return Err(format!("`{s}` is not a size"));
    }
    Ok((v * mult as f64) as u64)
}

/// The process's peak resident set so far (`VmHWM` of `/proc/self/status`), where the system
/// reports it.
pub fn peak_rss() -> Option<u64> {
    status_bytes("VmHWM:")
}

/// A `kB` field of `/proc/self/status`, in bytes.
fn status_bytes(field: &str) -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with(field))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Make freed large buffers leave the process at once (glibc): allocations of 1 MiB and more are
/// mapped and unmapped individually. glibc's default raises that threshold to the size of the
/// last large buffer freed (up to 32 MiB), after which matrices of a few MiB land in the heap and
/// stay resident when freed: a 600-patch bake then peaked 25 % over the sum of its live buffers.
/// Called once at the start of the binaries.
pub fn tune_allocator() {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: mallopt only sets a tuning parameter of the C allocator.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 1 << 20);
    }
}

/// The process's resident set now (`VmRSS`), where the system reports it.
pub fn current_rss() -> Option<u64> {
    status_bytes("VmRSS:")
}

/// Resident memory of the process that is not the work's buffers: `VmRSS` at the first call
/// (code, libraries), plus 2 MiB for the code the work pages in later (loaders, encoders, thread
/// stacks: a 16-triangle glTF bake peaked 2.0 MiB over the start), else 8 MiB where the system
/// does not report RSS. Plans add it to every stage's peak so that they compare with the
/// process's peak RSS.
pub fn baseline_rss() -> u64 {
    static BASE: std::sync::OnceLock<u64> = std::sync::OnceLock::new();
    *BASE.get_or_init(|| current_rss().map_or(8 << 20, |r| r + (2 << 20)))
}

/// Reset the peak resident set to the current one (`5` into `/proc/self/clear_refs`, Linux ≥
/// 4.0), so that [`peak_rss`] measures from here; false where the system cannot.
pub fn reset_peak_rss() -> bool {
    std::fs::write("/proc/self/clear_refs", "5").is_ok()
}

/// Refuse work whose estimated peak memory exceeds the budget.
pub fn check_memory(what: &str, estimate: u64, budget: u64) -> Result<()> {
    if estimate > budget {
        Err(Error::limit(format!(
            "{what} needs about {} of memory, over the budget of {} (raise --max-memory, or reduce the patch count / map size)",
            human_bytes(estimate),
            human_bytes(budget)
        )))
    } else {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    #[test]
    fn parses_sizes() {
        assert_eq!(parse_bytes("512M").unwrap(), 512 << 20);
        assert_eq!(parse_bytes("2G").unwrap(), 2 << 30);
        assert_eq!(parse_bytes("1000").unwrap(), 1000);
        assert!(parse_bytes("2X").is_err());
        assert!(parse_bytes("lots").is_err());
    }
}
