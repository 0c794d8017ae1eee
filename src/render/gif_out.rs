//! Frames to an animated GIF, written atomically.
//!
//! All frames share the global palette. After the first, each frame stores only the bounding box
//! of the pixels that changed, with unchanged pixels inside it set to the transparent index, so a
//! 100-step Box Pushing rollout stays in the tens of kilobytes.

use std::borrow::Cow;
use std::path::Path;

use super::palette::{gif_palette, TRANSPARENT};
use super::{Frame, RenderError};
use crate::files::atomic::write_atomic_try;
use std::io::Write;

/// How long the last frame of an episode ([`Frame::hold`]) stays up, unless the frame delay is
/// longer.
pub const HOLD_MS: u32 = 1500;

/// Browsers show delays under 20 ms as 100 ms, so shorter requests are raised to 20 ms.
const MIN_DELAY_MS: u32 = 20;

/// Encode `frames` as a looping GIF, each shown `frame_delay_ms` (a held frame at least
/// [`HOLD_MS`]), and write it to `path` via a temp file and a rename. Frames must all have the
/// size of the first; errors name `path`. [`write_gif_with`] streams frames instead.
pub fn write_gif(frames: &[Frame], path: &Path, frame_delay_ms: u32) -> Result<(), RenderError> {
    write_gif_with(path, frame_delay_ms, |gif| {
        frames.iter().try_for_each(|f| gif.push(f))
    })
}

/// Write a GIF to `path` whose frames `fill` pushes one at a time ([`GifWriter::push`]), so only
/// the previous frame is kept: a rollout of many episodes or a large grid takes the memory of
/// two frames, not of every frame. `path` is replaced (atomically) only if `fill` succeeds and
/// pushed at least one frame; `fill`'s value is returned.
pub fn write_gif_with<T>(
    path: &Path,
    frame_delay_ms: u32,
    fill: impl FnOnce(&mut GifWriter<'_>) -> Result<T, RenderError>,
) -> Result<T, RenderError> {
    let io_error = |source| RenderError::Io {
        path: path.to_path_buf(),
        source,
    };
    write_atomic_try(
        path,
        |out| {
            let mut gif = GifWriter {
                out: Some(out),
                encoder: None,
                previous: Vec::new(),
                size: (0, 0),
                frames: 0,
                frame_delay_ms,
                path,
            };
            let value = fill(&mut gif)?;
            gif.finish()?;
            Ok(value)
        },
        io_error,
    )
}

/// A GIF being written frame by frame ([`write_gif_with`]).
pub struct GifWriter<'a> {
    /// The file, until the first frame sizes the encoder.
    out: Option<&'a mut dyn Write>,
    encoder: Option<gif::Encoder<&'a mut dyn Write>>,
    /// The last frame's pixels: the next frame stores only what changed.
    previous: Vec<u8>,
    /// Frame 0's (width, height).
    size: (usize, usize),
    frames: usize,
    frame_delay_ms: u32,
    path: &'a Path,
}

impl GifWriter<'_> {
    /// Encode one frame. It must have the size of the first ([`RenderError::SizeMismatch`]);
    /// the first must fit a GIF ([`RenderError::TooLarge`]).
    pub fn push(&mut self, f: &Frame) -> Result<(), RenderError> {
        let path = self.path;
        let encode = |source| RenderError::Encode {
            path: path.to_path_buf(),
            source,
        };
        let (w, h) = (f.image.width(), f.image.height());
        let pixels = f.image.pixels();
        let ms = if f.hold {
            self.frame_delay_ms.max(HOLD_MS)
        } else {
            self.frame_delay_ms.max(MIN_DELAY_MS)
        };
        let delay = u16::try_from(ms.div_ceil(10)).unwrap_or(u16::MAX);
        match (&mut self.encoder, self.out.take()) {
            (None, Some(out)) => {
                let too_large = |_| RenderError::TooLarge {
                    path: path.to_path_buf(),
                    width: w,
                    height: h,
                };
                let (w16, h16) = (
                    u16::try_from(w).map_err(too_large)?,
                    u16::try_from(h).map_err(too_large)?,
                );
                let mut enc = gif::Encoder::new(out, w16, h16, &gif_palette()).map_err(encode)?;
                enc.set_repeat(gif::Repeat::Infinite).map_err(encode)?;
                enc.write_frame(&gif::Frame {
                    width: w16,
                    height: h16,
                    buffer: Cow::Borrowed(pixels),
                    delay,
                    ..gif::Frame::default()
                })
                .map_err(encode)?;
                self.encoder = Some(enc);
                self.size = (w, h);
                self.previous = pixels.to_vec();
            }
            (Some(enc), _) => {
                if (w, h) != self.size {
                    return Err(RenderError::SizeMismatch {
                        path: path.to_path_buf(),
                        index: self.frames,
                        got: (w, h),
                        expected: self.size,
                    });
                }
                enc.write_frame(&changed_patch(&self.previous, pixels, w, delay))
                    .map_err(encode)?;
                self.previous.copy_from_slice(pixels);
            }
            (None, None) => unreachable!("the file is handed to the encoder with frame 0"),
        }
        self.frames += 1;
        Ok(())
    }

    /// Frames pushed so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Write the GIF's trailer; [`RenderError::NoFrames`] if nothing was pushed.
    fn finish(self) -> Result<(), RenderError> {
        let path = self.path;
        match self.encoder {
            None => Err(RenderError::NoFrames {
                path: path.to_path_buf(),
            }),
            Some(enc) => enc
                .into_inner()
                .map(drop)
                .map_err(|source| RenderError::Io {
                    path: path.to_path_buf(),
                    source,
                }),
        }
    }
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
