//! Image outputs (terrain masks, lit fractions, player frames, study plots): 8/16-bit grayscale PNG and f32 EXR, always atomically (a temporary
//! file beside the target, renamed into place only when complete).

use crate::error::{Error, IoContext, Result};
use std::path::{Path, PathBuf};

/// Write `path` through `write(tmp)`: the temporary sibling is renamed onto `path` only when
/// `write` succeeded; on failure it is removed and `path` is left as it was.
pub fn write_atomic(path: &Path, write: impl FnOnce(&Path) -> Result<()>) -> Result<()> {
    let parent = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    if !parent.is_dir() {
        return Err(Error::input(
            path,
            format!("the output directory {} does not exist", parent.display()),
        ));
    }
    let name = path
        .file_name()
        .ok_or_else(|| Error::input(path, "the output path has no file name"))?
        .to_string_lossy()
        .into_owned();
    // Keep the extension last so that writers choosing by extension see the real one.
    let tmp = parent.join(format!(".relume-tmp-{}-{name}", std::process::id()));
    match write(&tmp) {
        Ok(()) => std::fs::rename(&tmp, path).at(path, "cannot move the finished file into place"),
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e)
        }
    }
}

/// Write an 8-bit grayscale PNG atomically.
pub fn write_png_gray8(path: &Path, width: usize, height: usize, pixels: Vec<u8>) -> Result<()> {
    let img = image::GrayImage::from_raw(width as u32, height as u32, pixels)
        .ok_or_else(|| Error::Internal("PNG buffer size mismatch".into()))?;
    write_atomic(path, |tmp| {
        img.save_with_format(tmp, image::ImageFormat::Png)
            .map_err(|e| image_error(tmp, e))
    })
}

/// Write an RGBA image as PNG, atomically.
pub fn write_png_rgba(path: &Path, img: &image::RgbaImage) -> Result<()> {
    let mut bytes = Vec::new();
    img.write_to(
        &mut std::io::Cursor::new(&mut bytes),
        image::ImageFormat::Png,
    )
    .map_err(|e| Error::Internal(format!("PNG encoding failed: {e}")))?;
    write_atomic(path, |tmp| {
        std::fs::write(tmp, &bytes).map_err(|e| Error::io(tmp, "cannot write", e))
    })
}

/// Write a 16-bit grayscale PNG atomically.
pub fn write_png_gray16(path: &Path, width: usize, height: usize, pixels: Vec<u16>) -> Result<()> {
    let img = image::ImageBuffer::<image::Luma<u16>, Vec<u16>>::from_raw(
        width as u32,
        height as u32,
        pixels,
    )
    .ok_or_else(|| Error::Internal("PNG buffer size mismatch".into()))?;
    write_atomic(path, |tmp| {
        img.save_with_format(tmp, image::ImageFormat::Png)
            .map_err(|e| image_error(tmp, e))
    })
}

/// Write a one-channel (`Y`) f32 EXR atomically.
pub fn write_exr_gray(path: &Path, width: usize, height: usize, values: &[f32]) -> Result<()> {
    write_atomic(path, |tmp| {
        super::exr_io::write_f32_channels(tmp, width, height, &[("Y", values)])
    })
}

/// Is this an EXR path (by extension)?
pub fn is_exr(path: &Path) -> bool {
    matches!(
        path.extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref(),
        Some("exr")
    )
}

/// Whether `path` ends in `.tif` or `.tiff` (any case).
pub fn is_tiff(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("tif") || e.eq_ignore_ascii_case("tiff"))
}

/// Refuse output paths whose extension is not one of `allowed`.
pub fn check_extension(path: &Path, allowed: &[&str]) -> Result<()> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if ext.as_deref().is_some_and(|e| allowed.contains(&e)) {
        Ok(())
    } else {
        Err(Error::unsupported(
            path,
            format!(
                "cannot write this file type; use one of: {}",
                allowed
                    .iter()
                    .map(|a| format!(".{a}"))
                    .collect::<Vec<_>>()
                    .join(" ")
            ),
        ))
    }
}

fn image_error(path: &Path, e: image::ImageError) -> Error {
    match e {
        image::ImageError::IoError(io) => Error::io(path, "cannot write image", io),
        other => Error::input(path, format!("cannot encode image: {other}")),
    }
}
