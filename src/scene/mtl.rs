//! MTL texture statements as files in the wild write them (`map_Kd`, `map_d`): options before the
//! file name, Windows paths, and names whose case differs from the file on disk.
//!
//! A statement is `map_Kd [-option value…]… file name`. Options follow the MTL specification
//! (Wavefront, 1995): `-o`, `-s`, `-t` take one to three numbers; `-mm` two; `-blendu`, `-blendv`,
//! `-bm`, `-boost`, `-cc`, `-clamp`, `-imfchan`, `-texres`, `-type` one. Of these `-o` (offset),
//! `-s` (scale), `-clamp on` and `-imfchan` change what a diffuse albedo or an alpha mask reads; the
//! others (bump and colour-correction settings) are skipped. The rest of the line is the file name,
//! spaces included.

use super::texture::{Channel, TextureRef, Wrap};
use std::path::{Component, Path, PathBuf};

/// A parsed texture statement.
#[derive(Clone, Debug, PartialEq)]
pub struct TextureStatement {
    /// The file name as written, backslashes turned into slashes.
    pub file: String,
    /// `-o u v`: offset of the texture coordinates (OBJ convention, origin bottom-left).
    pub offset: [f32; 2],
    /// `-s u v`: scale of the texture coordinates.
    pub scale: [f32; 2],
    /// `-clamp on`.
    pub clamp: bool,
    /// `-imfchan r|g|b|m|l`: the channel a scalar texture reads (`m`, matte, is alpha).
    pub channel: Option<Channel>,
}

/// Options and how many values each takes (`(min, max)`; numbers are taken greedily up to max).
fn arity(option: &str) -> Option<(usize, usize)> {
    Some(match option {
        "-o" | "-s" | "-t" => (1, 3),
        "-mm" => (2, 2),
        "-blendu" | "-blendv" | "-bm" | "-boost" | "-cc" | "-clamp" | "-imfchan" | "-texres"
        | "-type" => (1, 1),
        _ => return None,
    })
}

/// Parse the value of a texture statement (everything after `map_Kd`). Errors describe the
/// problem; the caller names the file and material.
pub fn parse_statement(value: &str) -> Result<TextureStatement, String> {
    let mut st = TextureStatement {
        file: String::new(),
        offset: [0.0; 2],
        scale: [1.0; 2],
        clamp: false,
        channel: None,
    };
    let mut rest = value.trim();
    while rest.starts_with('-') {
        let (option, after) = split_word(rest);
        let Some((min, max)) = arity(option) else {
            return Err(format!("unknown texture option `{option}`"));
        };
        let mut values = Vec::new();
        let mut after = after;
        while values.len() < max {
            let (word, next) = split_word(after);
            if word.is_empty() {
                break;
            }
            let numeric = word.parse::<f32>().is_ok();
            if values.len() >= min && !numeric {
                break;
            }
            values.push(word);
            after = next;
        }
        if values.len() < min {
            return Err(format!("texture option `{option}` needs {min} value(s)"));
        }
        let number = |i: usize| -> Result<Option<f32>, String> {
            values
                .get(i)
                .map(|w| {
                    w.parse::<f32>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| format!("texture option `{option}`: `{w}` is not a number"))
                })
                .transpose()
        };
        match option {
            "-o" => st.offset = [number(0)?.unwrap_or(0.0), number(1)?.unwrap_or(0.0)],
            "-s" => st.scale = [number(0)?.unwrap_or(1.0), number(1)?.unwrap_or(1.0)],
            "-clamp" => st.clamp = values[0].eq_ignore_ascii_case("on"),
            "-imfchan" => {
                st.channel = Some(match values[0] {
                    "r" => Channel::Red,
                    "g" => Channel::Green,
                    "b" => Channel::Blue,
                    "m" => Channel::Alpha,
                    "l" => Channel::Luminance,
                    other => return Err(format!("`-imfchan {other}` is not r, g, b, m or l")),
                })
            }
            _ => {}
        }
        rest = after;
    }
    if rest.is_empty() {
        return Err("texture statement names no file".into());
    }
    st.file = rest.replace('\\', "/");
    Ok(st)
}

fn split_word(s: &str) -> (&str, &str) {
    let s = s.trim_start();
    match s.find(char::is_whitespace) {
        Some(i) => (&s[..i], s[i..].trim_start()),
        None => (s, ""),
    }
}

impl TextureStatement {
    /// The reference to texture `texture` this statement makes: `-s`/`-o` applied in OBJ's frame
    /// (origin bottom-left), expressed in the loader's flipped frame `v_g = 1 − v_obj`:
    /// `v' = 1 − (s_v·(1 − v_g) + o_v) = s_v·v_g + (1 − s_v − o_v)`.
    pub fn reference(&self, texture: u32) -> TextureRef {
        let [su, sv] = self.scale;
        let [ou, ov] = self.offset;
        TextureRef {
            texture,
            transform: [[su, 0.0, ou], [0.0, sv, 1.0 - sv - ov]],
            wrap: [if self.clamp {
                Wrap::ClampToEdge
            } else {
                Wrap::Repeat
            }; 2],
        }
    }
}

/// Where a texture file named in an MTL is: `dir` joined with `file`. When that path does not
/// exist, each component is looked up case-insensitively; the second value is then the name
/// found (for a warning naming both). None when neither exists.
pub fn resolve(dir: &Path, file: &str) -> Option<(PathBuf, bool)> {
    let named = dir.join(file);
    if named.is_file() {
        return Some((named, false));
    }
    let mut found = dir.to_path_buf();
    for component in Path::new(file).components() {
        match component {
            Component::Normal(name) => {
                let exact = found.join(name);
                if exact.exists() {
                    found = exact;
                    continue;
                }
                let name = name.to_str()?;
                let entry = std::fs::read_dir(&found).ok()?.flatten().find(|e| {
                    e.file_name()
                        .to_str()
                        .is_some_and(|n| n.eq_ignore_ascii_case(name))
                })?;
                found = entry.path();
            }
            other => found.push(other.as_os_str()),
        }
    }
    found.is_file().then_some((found, true))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn options_before_the_file_name() {
        let st =
            parse_statement("-s 2 3 1 -o 0.5 0.25 -bm 0.3 -clamp on textures\\a b.png").unwrap();
        assert_eq!(st.file, "textures/a b.png");
        assert_eq!(st.scale, [2.0, 3.0]);
        assert_eq!(st.offset, [0.5, 0.25]);
        assert!(st.clamp);
        let st = parse_statement("-s 2 file.png").unwrap();
        assert_eq!((st.scale, st.file.as_str()), ([2.0, 1.0], "file.png"));
        let st = parse_statement("-imfchan m mask.png").unwrap();
        assert_eq!(st.channel, Some(Channel::Alpha));
    }

    #[test]
    fn bad_statements_say_what_is_wrong() {
        assert!(parse_statement("-s").unwrap_err().contains("needs 1"));
        assert!(parse_statement("-zz 1 a.png")
            .unwrap_err()
            .contains("unknown"));
        assert!(parse_statement("-s 1 1").unwrap_err().contains("no file"));
        assert!(parse_statement("-imfchan q a.png")
            .unwrap_err()
            .contains("imfchan"));
    }

    #[test]
    fn scale_and_offset_act_in_obj_frame() {
        let st = parse_statement("-s 2 4 -o 0.5 0.25 a.png").unwrap();
        let r = st.reference(0);
        // OBJ (u, v) = (0.1, 0.2) → OBJ' (0.7, 1.05) → flipped v' = 1 − 1.05 = −0.05.
        let [u, v] = r.apply([0.1, 1.0 - 0.2]);
        assert!((u - 0.7).abs() < 1e-6 && (v + 0.05).abs() < 1e-6, "{u} {v}");
    }
}
