//! Image dumps for the renderer and debugging: PNG (8-bit RGBA) and OpenEXR (f32 RGBA), both
//! written atomically.

use std::path::Path;

use crate::atomic::atomic_write;
use crate::error::IoError;

/// Checks that a buffer of `len` pixels matches `width × height` (and that neither is zero).
fn check_size(path: &Path, width: u32, height: u32, len: usize, unit: &str) -> Result<(), IoError> {
    let expected = width as u64 * height as u64;
    if width == 0 || height == 0 || len as u64 != expected {
        return Err(IoError::InvalidInput {
            path: path.to_path_buf(),
            message: format!(
                "image buffer has {len} {unit}, expected {width}×{height} = {expected} (non-empty)"
            ),
        });
    }
    Ok(())
}

/// Writes an 8-bit RGBA PNG. `data` is row-major from the top row, 4 bytes per pixel, so
/// `data.len() == 4 · width · height` (else an error, nothing written).
pub fn write_png_rgba8(path: &Path, width: u32, height: u32, data: &[u8]) -> Result<(), IoError> {
    if !data.len().is_multiple_of(4) {
        return Err(IoError::InvalidInput {
            path: path.to_path_buf(),
            message: format!("RGBA8 buffer length {} is not a multiple of 4", data.len()),
        });
    }
    check_size(path, width, height, data.len() / 4, "pixels")?;
    atomic_write(path, |w| {
        use image::ImageEncoder;
        image::codecs::png::PngEncoder::new(w)
            .write_image(data, width, height, image::ExtendedColorType::Rgba8)
            .map_err(std::io::Error::other)
    })
}

/// Writes a 32-bit float RGBA OpenEXR image. `data` is row-major from the top row, one
/// `[r, g, b, a]` per pixel, so `data.len() == width · height` (else an error, nothing written).
pub fn write_exr_rgba(
    path: &Path,
    width: u32,
    height: u32,
    data: &[[f32; 4]],
) -> Result<(), IoError> {
    use exr::prelude::{Image, SpecificChannels, Vec2, WritableImage};
    check_size(path, width, height, data.len(), "pixels")?;
    let w = width as usize;
    let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
        let [r, g, b, a] = data[y * w + x];
        (r, g, b, a)
    });
    // exr needs `Write + Seek`: encode into memory, then write the bytes atomically.
    let mut encoded = std::io::Cursor::new(Vec::new());
    Image::from_channels((w, height as usize), channels)
        .write()
        .to_buffered(&mut encoded)
        .map_err(|e| IoError::InvalidInput {
            path: path.to_path_buf(),
            message: format!("EXR encoding failed: {e}"),
        })?;
    atomic_write(path, |out| out.write_all(encoded.get_ref()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn png_writes_a_decodable_image() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        let data: Vec<u8> = (0..2 * 3 * 4).map(|i| i as u8 * 10).collect();
        write_png_rgba8(&path, 2, 3, &data).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        let decoded = image::load_from_memory(&bytes).unwrap().to_rgba8();
        assert_eq!(decoded.dimensions(), (2, 3));
        assert_eq!(decoded.as_raw(), &data);
    }

    #[test]
    fn exr_writes_a_decodable_image() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        let data: Vec<[f32; 4]> = (0..6).map(|i| [i as f32, 0.5, -1.0, 1.0]).collect();
        write_exr_rgba(&path, 3, 2, &data).unwrap();
        let img = exr::prelude::read_first_rgba_layer_from_file(
            &path,
            |size, _| vec![[0.0f32; 4]; size.width() * size.height()],
            |px: &mut Vec<[f32; 4]>, pos, (r, g, b, a): (f32, f32, f32, f32)| {
                px[pos.y() * 3 + pos.x()] = [r, g, b, a];
            },
        )
        .unwrap();
        assert_eq!(img.layer_data.channel_data.pixels, data);
    }

    #[test]
    fn wrong_buffer_size_is_an_error_and_writes_nothing() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        let err = write_png_rgba8(&path, 2, 2, &[0; 12]).unwrap_err();
        assert!(err.to_string().contains("a.png"), "{err}");
        assert!(!path.exists());
        let path = dir.path().join("a.exr");
        assert!(write_exr_rgba(&path, 2, 2, &[[0.0; 4]; 3]).is_err());
        assert!(!path.exists());
    }
}
