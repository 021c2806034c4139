//! Scripted input for the window (`relume-player DIR --panel-script FILE`): input events the
//! panel receives through egui's own input path, so a test drives it as a person would. One
//! step per line, `#` comments:
//!
//! ```text
//! 5 click Sun           # frame 5: press on the widget labelled "Sun", release on frame 6
//! 9 screenshot a.png    # frame 9: write the player's frame (no panel) to a.png
//! 9 window w.png        # frame 9: write the window as shown (frame and panel) to w.png
//! ```
//!
//! Labels are those of [`super::WidgetRects`]: `Sun`, `Sun −15°`, `Sun +15°`, `Light 0`, …,
//! `Automatic exposure`, the pass names, `Camera mode`, `Copy camera`, `Screenshot`.

use crate::error::{Error, Result};
use std::path::{Path, PathBuf};

/// One scripted step.
#[derive(Clone, Debug, PartialEq)]
pub enum Step {
    /// Move the pointer to the widget's centre and press (`true`) or release (`false`).
    Pointer { label: String, pressed: bool },
    /// Write the player's frame as a PNG.
    Screenshot(PathBuf),
    /// Write what the window shows (frame and panel) as a PNG, where the surface allows
    /// copies.
    Window(PathBuf),
}

/// Steps by frame.
#[derive(Clone, Debug, Default)]
pub struct Script {
    steps: Vec<(u32, Step)>,
}

impl Script {
    /// Read a script file (relative screenshot paths are relative to it).
    pub fn read(path: &Path) -> Result<Script> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| Error::io(path, "cannot read the panel script", e))?;
        let base = path.parent().unwrap_or(Path::new("."));
        let mut steps = Vec::new();
        for (n, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let bad = |what: &str| Error::input(path, format!("line {}: {what}", n + 1));
            let (frame, rest) = line
                .split_once(char::is_whitespace)
                .ok_or_else(|| bad("expected FRAME ACTION ARGUMENT"))?;
            let frame: u32 = frame
                .parse()
                .map_err(|_| bad(&format!("`{frame}` is not a frame number")))?;
            let (action, arg) = rest
                .trim()
                .split_once(char::is_whitespace)
                .unwrap_or((rest, ""));
            let arg = arg.trim();
            match action {
                "click" if !arg.is_empty() => {
                    steps.push((
                        frame,
                        Step::Pointer {
                            label: arg.into(),
                            pressed: true,
                        },
                    ));
                    steps.push((
                        frame + 1,
                        Step::Pointer {
                            label: arg.into(),
                            pressed: false,
                        },
                    ));
                }
                "screenshot" if !arg.is_empty() => {
                    steps.push((frame, Step::Screenshot(base.join(arg))))
                }
                "window" if !arg.is_empty() => steps.push((frame, Step::Window(base.join(arg)))),
                _ => {
                    return Err(bad(&format!(
                        "unknown step `{rest}` (click LABEL, screenshot PNG, window PNG)"
                    )))
                }
            }
        }
        Ok(Script { steps })
    }

    /// The steps of frame `frame`, in file order.
    pub fn due(&self, frame: u32) -> impl Iterator<Item = &Step> {
        self.steps
            .iter()
            .filter(move |(f, _)| *f == frame)
            .map(|(_, s)| s)
    }
}

/// egui events for a pointer step on a widget at `rect` (points).
pub fn pointer_events(rect: egui::Rect, pressed: bool) -> [egui::Event; 2] {
    let pos = rect.center();
    [
        egui::Event::PointerMoved(pos),
        egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: Default::default(),
        },
    ]
}
