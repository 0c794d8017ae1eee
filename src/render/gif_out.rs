//! Frames to an animated GIF, written atomically.
//!
//! All frames share the global palette. After the first, each frame stores only the bounding box
//! of the pixels that changed, with unchanged pixels inside it set to the transparent index, so a
//! 100-step Box Pushing rollout stays in the tens of kilobytes.

use std::borrow::Cow;
use std::path::Path;

use super::palette::{gif_palette, TRANSPARENT};
use super::{Frame, RenderError};
use crate::files::atomic::write_atomic;

/// How long the last frame of an episode ([`Frame::hold`]) stays up, unless the frame delay is
/// longer.
pub const HOLD_MS: u32 = 1500;

/// Browsers show delays under 20 ms as 100 ms, so shorter requests are raised to 20 ms.
const MIN_DELAY_MS: u32 = 20;

/// Encode `frames` as a looping GIF, each shown `frame_delay_ms` (a held frame at least
/// [`HOLD_MS`]), and write it to `path` via a temp file and a rename. Frames must all have the
/// size of the first; errors name `path`.
pub fn write_gif(frames: &[Frame], path: &Path, frame_delay_ms: u32) -> Result<(), RenderError> {
    let first = frames.first().ok_or_else(|| RenderError::NoFrames {
        path: path.to_path_buf(),
    })?;
    let (w, h) = (first.image.width(), first.image.height());
    let too_large = |_| RenderError::TooLarge {
        path: path.to_path_buf(),
        width: w,
        height: h,
    };
    let (w16, h16) = (
        u16::try_from(w).map_err(too_large)?,
        u16::try_from(h).map_err(too_large)?,
    );
    if let Some((index, f)) = frames
        .iter()
        .enumerate()
        .find(|(_, f)| (f.image.width(), f.image.height()) != (w, h))
    {
        return Err(RenderError::SizeMismatch {
            path: path.to_path_buf(),
            index,
            got: (f.image.width(), f.image.height()),
            expected: (w, h),
        });
    }
    let encode = |source| RenderError::Encode {
        path: path.to_path_buf(),
        source,
    };

    let mut bytes = Vec::new();
    {
        let mut enc = gif::Encoder::new(&mut bytes, w16, h16, &gif_palette()).map_err(encode)?;
        enc.set_repeat(gif::Repeat::Infinite).map_err(encode)?;
        let mut prev: Option<&[u8]> = None;
        for f in frames {
            let pixels = f.image.pixels();
            let ms = if f.hold {
                frame_delay_ms.max(HOLD_MS)
            } else {
                frame_delay_ms.max(MIN_DELAY_MS)
            };
            let delay = u16::try_from(ms.div_ceil(10)).unwrap_or(u16::MAX);
            let frame = match prev {
                None => gif::Frame {
                    width: w16,
                    height: h16,
                    buffer: Cow::Borrowed(pixels),
                    delay,
                    ..gif::Frame::default()
                },
                Some(before) => changed_patch(before, pixels, w, delay),
            };
            enc.write_frame(&frame).map_err(encode)?;
            prev = Some(pixels);
        }
    }
    write_atomic(path, &bytes).map_err(|source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    })
}

/// The part of `now` that differs from `before` (both `width` wide), as a sub-frame whose
/// unchanged pixels are transparent. An unchanged picture gives one transparent pixel.
fn changed_patch<'a>(before: &[u8], now: &[u8], width: usize, delay: u16) -> gif::Frame<'a> {
    let (mut x0, mut y0, mut x1, mut y1) = (usize::MAX, usize::MAX, 0, 0);
    for (i, (a, b)) in before.iter().zip(now).enumerate() {
        if a != b {
            let (x, y) = (i % width, i / width);
            x0 = x0.min(x);
            x1 = x1.max(x);
            y0 = y0.min(y);
            y1 = y1.max(y);
        }
    }
    if x0 == usize::MAX {
        (x0, y0, x1, y1) = (0, 0, 0, 0);
    }
    let mut patch = Vec::with_capacity((x1 - x0 + 1) * (y1 - y0 + 1));
    for y in y0..=y1 {
        let row = y * width;
        for x in x0..=x1 {
            let p = now[row + x];
            patch.push(if p == before[row + x] { TRANSPARENT } else { p });
        }
    }
    gif::Frame {
        left: x0 as u16,
        top: y0 as u16,
        width: (x1 - x0 + 1) as u16,
        height: (y1 - y0 + 1) as u16,
        transparent: Some(TRANSPARENT),
        buffer: Cow::Owned(patch),
        delay,
        ..gif::Frame::default()
    }
}
