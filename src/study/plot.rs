//! Log-log scatter plots of a sweep, drawn by hand into an RGB image (the `image` crate is
//! already a dependency; a plotting library would add a font stack for a few labels). Points of
//! the same series are joined in x order; points whose x or y is not positive and finite (e.g.
//! the reference's error of exactly 0) cannot sit on a log axis and are counted in a footnote.
//! Text uses a built-in 5x7 pixel font (upper case, digits, a little punctuation).

use super::{PlotSpec, Sweep};
use image::{Rgb, RgbImage};

pub const WIDTH: u32 = 960;
pub const HEIGHT: u32 = 600;
const LEFT: i64 = 90;
const RIGHT: i64 = 250;
const TOP: i64 = 60;
const BOTTOM: i64 = 70;

const WHITE: Rgb<u8> = Rgb([255, 255, 255]);
const BLACK: Rgb<u8> = Rgb([0, 0, 0]);
const GRID: Rgb<u8> = Rgb([225, 225, 225]);
const MINOR: Rgb<u8> = Rgb([242, 242, 242]);
/// Tableau 10.
const PALETTE: [[u8; 3]; 10] = [
    [31, 119, 180],
    [255, 127, 14],
    [44, 160, 44],
    [214, 39, 40],
    [148, 103, 189],
    [140, 86, 75],
    [227, 119, 194],
    [127, 127, 127],
    [188, 189, 34],
    [23, 190, 207],
];

/// 5x7 glyphs: 7 rows, bit 4 = leftmost column.
const FONT: &[(char, [u8; 7])] = &[
    ('A', [0x0E, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11]),
    ('B', [0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E]),
    ('C', [0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E]),
    ('D', [0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C]),
    ('E', [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F]),
    ('F', [0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10]),
    ('G', [0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F]),
    ('H', [0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11]),
    ('I', [0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E]),
    ('J', [0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C]),
    ('K', [0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11]),
    ('L', [0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F]),
    ('M', [0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11]),
    ('N', [0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11]),
    ('O', [0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E]),
    ('P', [0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10]),
    ('Q', [0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D]),
    ('R', [0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11]),
    ('S', [0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E]),
    ('T', [0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04]),
    ('U', [0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E]),
    ('V', [0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04]),
    ('W', [0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A]),
    ('X', [0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11]),
    ('Y', [0x11, 0x11, 0x0A, 0x04, 0x04, 0x04, 0x04]),
    ('Z', [0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F]),
    ('0', [0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E]),
    ('1', [0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E]),
    ('2', [0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F]),
    ('3', [0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E]),
    ('4', [0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02]),
    ('5', [0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E]),
    ('6', [0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E]),
    ('7', [0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08]),
    ('8', [0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E]),
    ('9', [0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C]),
    (' ', [0, 0, 0, 0, 0, 0, 0]),
    ('.', [0, 0, 0, 0, 0, 0x0C, 0x0C]),
    (',', [0, 0, 0, 0, 0x0C, 0x04, 0x08]),
    ('-', [0, 0, 0, 0x1F, 0, 0, 0]),
    ('+', [0, 0x04, 0x04, 0x1F, 0x04, 0x04, 0]),
    ('_', [0, 0, 0, 0, 0, 0, 0x1F]),
    ('(', [0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02]),
    (')', [0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08]),
    ('/', [0, 0x01, 0x02, 0x04, 0x08, 0x10, 0]),
    (':', [0, 0x0C, 0x0C, 0, 0x0C, 0x0C, 0]),
    ('%', [0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03]),
    ('=', [0, 0, 0x1F, 0, 0x1F, 0, 0]),
    ('^', [0x04, 0x0A, 0x11, 0, 0, 0, 0]),
    ('°', [0x0C, 0x12, 0x12, 0x0C, 0, 0, 0]),
    ('|', [0x04, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04]),
    ('?', [0x0E, 0x11, 0x01, 0x02, 0x04, 0, 0x04]),
];

fn glyph(c: char) -> [u8; 7] {
    let c = c.to_ascii_uppercase();
    FONT.iter()
        .find(|g| g.0 == c)
        .or_else(|| FONT.iter().find(|g| g.0 == '?'))
        .map(|g| g.1)
        .unwrap()
}

/// What the font cannot show, spelled with what it can.
fn plain(text: &str) -> String {
    text.replace('∞', "inf")
        .replace('²', "^2")
        .replace('·', ".")
        .replace('×', "x")
        .replace(['−', '–'], "-")
        .replace('µ', "u")
}

/// Width in pixels of `text` at `scale`.
pub fn text_width(text: &str, scale: i64) -> i64 {
    plain(text).chars().count() as i64 * 6 * scale
}

/// Draw `text` with its top-left corner at (x, y).
pub fn draw_text(img: &mut RgbImage, x: i64, y: i64, text: &str, scale: i64, color: Rgb<u8>) {
    for (k, c) in plain(text).chars().enumerate() {
        let g = glyph(c);
        let x0 = x + k as i64 * 6 * scale;
        for (row, bits) in g.iter().enumerate() {
            for col in 0..5 {
                if bits & (0x10 >> col) != 0 {
                    fill_rect(
                        img,
                        x0 + col * scale,
                        y + row as i64 * scale,
                        scale,
                        scale,
                        color,
                    );
                }
            }
        }
    }
}

fn put(img: &mut RgbImage, x: i64, y: i64, c: Rgb<u8>) {
    if x >= 0 && y >= 0 && (x as u32) < img.width() && (y as u32) < img.height() {
        img.put_pixel(x as u32, y as u32, c);
    }
}

fn fill_rect(img: &mut RgbImage, x: i64, y: i64, w: i64, h: i64, c: Rgb<u8>) {
    for yy in y..y + h {
        for xx in x..x + w {
            put(img, xx, yy, c);
        }
    }
}

/// A line two pixels thick (Bresenham).
fn line(img: &mut RgbImage, (x0, y0): (i64, i64), (x1, y1): (i64, i64), c: Rgb<u8>) {
    let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
    let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
    let (mut x, mut y, mut err) = (x0, y0, dx + dy);
    loop {
        put(img, x, y, c);
        put(img, x + 1, y, c);
        put(img, x, y + 1, c);
        if x == x1 && y == y1 {
            return;
        }
        let e2 = 2 * err;
        if e2 >= dy {
            err += dy;
            x += sx;
        }
        if e2 <= dx {
            err += dx;
            y += sy;
        }
    }
}

/// A log10 axis over whole decades covering `values`.
struct Axis {
    lo: f64,
    hi: f64,
}

impl Axis {
    fn covering(values: impl Iterator<Item = f64>) -> Axis {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for v in values {
            lo = lo.min(v.log10());
            hi = hi.max(v.log10());
        }
        if !lo.is_finite() {
            return Axis { lo: 0.0, hi: 1.0 };
        }
        let (lo, mut hi) = (lo.floor(), hi.ceil());
        if hi <= lo {
            hi = lo + 1.0;
        }
        Axis { lo, hi }
    }

    /// Position in [0, 1].
    fn at(&self, v: f64) -> f64 {
        (v.log10() - self.lo) / (self.hi - self.lo)
    }

    /// (value, labelled) ticks: decades, plus 2 and 5 labelled on short axes.
    fn ticks(&self) -> Vec<(f64, bool)> {
        let short = self.hi - self.lo <= 2.0;
        let mut out = Vec::new();
        for e in self.lo as i32..=self.hi as i32 {
            let d = 10f64.powi(e);
            out.push((d, true));
            if e < self.hi as i32 {
                for m in 2..10 {
                    out.push((d * m as f64, short && (m == 2 || m == 5)));
                }
            }
        }
        out
    }
}

fn tick_label(v: f64) -> String {
    let e = v.log10().floor() as i32;
    let m = (v / 10f64.powi(e)).round() as i32;
    match e {
        0 => format!("{m}"),
        1 | 2 if m == 1 => format!("{}", 10i64.pow(e as u32)),
        _ => format!("{m}e{e}"),
    }
}

/// A plotted setting: x, y (0 = exact: drawn on the bottom edge), label, relume's default?
struct Point {
    x: f64,
    y: f64,
    label: String,
    default: bool,
}

/// Draw one plot of `sweep`.
pub fn draw(spec: &PlotSpec, sweep: &Sweep) -> RgbImage {
    let mut img = RgbImage::from_pixel(WIDTH, HEIGHT, WHITE);
    let (w, h) = (WIDTH as i64, HEIGHT as i64);
    let (x0, x1, y0, y1) = (LEFT, w - RIGHT, TOP, h - BOTTOM);
    // Series in order of first appearance; points with positive finite coordinates.
    let mut series: Vec<(String, Vec<Point>)> = Vec::new();
    let mut skipped = 0;
    for s in &sweep.settings {
        match (s.value(&spec.x), s.value(&spec.y)) {
            // An error of exactly 0 has no place on a log axis: it sits on the bottom edge.
            (Some(x), Some(y)) if x > 0.0 && y >= 0.0 && x.is_finite() && y.is_finite() => {
                let p = Point {
                    x,
                    y,
                    label: s.label.clone(),
                    default: s.default,
                };
                match series.iter_mut().find(|e| e.0 == s.series) {
                    Some(e) => e.1.push(p),
                    None => series.push((s.series.clone(), vec![p])),
                }
            }
            _ => skipped += 1,
        }
    }
    let all = || series.iter().flat_map(|s| s.1.iter());
    let exact = all().filter(|p| p.y == 0.0).count();
    let any_default = all().any(|p| p.default);
    let ax = Axis::covering(all().map(|p| p.x));
    let ay = Axis::covering(all().map(|p| p.y).filter(|&y| y > 0.0));
    let px = |v: f64| x0 + (ax.at(v) * (x1 - x0) as f64).round() as i64;
    // Settings with error 0 get their own row under the log axis, labelled 0.
    let zero_row = if exact > 0 { 24 } else { 0 };
    let yl = y1 - zero_row;
    let py = |v: f64| {
        if v > 0.0 {
            yl - (ay.at(v) * (yl - y0) as f64).round() as i64
        } else {
            y1 - zero_row / 2
        }
    };
    for (v, labelled) in ax.ticks() {
        let x = px(v);
        line(
            &mut img,
            (x, y0),
            (x, y1),
            if labelled { GRID } else { MINOR },
        );
        if labelled {
            let t = tick_label(v);
            draw_text(&mut img, x - text_width(&t, 1) / 2, y1 + 8, &t, 1, BLACK);
        }
    }
    for (v, labelled) in ay.ticks() {
        let y = py(v);
        line(
            &mut img,
            (x0, y),
            (x1, y),
            if labelled { GRID } else { MINOR },
        );
        if labelled {
            let t = tick_label(v);
            draw_text(&mut img, x0 - 8 - text_width(&t, 1), y - 3, &t, 1, BLACK);
        }
    }
    if exact > 0 {
        line(&mut img, (x0, yl + 4), (x1, yl + 4), BLACK);
        draw_text(
            &mut img,
            x0 - 8 - text_width("0", 1),
            py(0.0) - 3,
            "0",
            1,
            BLACK,
        );
    }
    // Frame.
    for (a, b) in [
        ((x0, y0), (x1, y0)),
        ((x1, y0), (x1, y1)),
        ((x1, y1), (x0, y1)),
        ((x0, y1), (x0, y0)),
    ] {
        line(&mut img, a, b, BLACK);
    }
    let label_points = all().count() <= 12;
    for (k, (name, points)) in series.iter_mut().enumerate() {
        let c = Rgb(PALETTE[k % PALETTE.len()]);
        points.sort_by(|a, b| a.x.total_cmp(&b.x));
        for pair in points.windows(2) {
            line(
                &mut img,
                (px(pair[0].x), py(pair[0].y)),
                (px(pair[1].x), py(pair[1].y)),
                c,
            );
        }
        for p in points.iter() {
            let (x, y) = (px(p.x), py(p.y));
            fill_rect(&mut img, x - 3, y - 3, 7, 7, c);
            if p.default {
                ring(&mut img, x, y, 7, BLACK);
                ring(&mut img, x, y, 8, BLACK);
            }
            if label_points {
                draw_text(&mut img, x + 6, y - 12, &p.label, 1, c);
            }
        }
        // Legend.
        let ly = y0 + 10 + 16 * k as i64;
        fill_rect(&mut img, x1 + 16, ly, 10, 7, c);
        draw_text(&mut img, x1 + 32, ly, name, 1, BLACK);
    }
    draw_text(&mut img, LEFT, 14, &spec.title, 2, BLACK);
    draw_text(
        &mut img,
        LEFT,
        TOP - 14,
        &format!("y: {} (log)", spec.y_label),
        1,
        BLACK,
    );
    let xl = format!("x: {} (log)", spec.x_label);
    draw_text(
        &mut img,
        (x0 + x1 - text_width(&xl, 1)) / 2,
        y1 + 26,
        &xl,
        1,
        BLACK,
    );
    if any_default {
        let ly = y0 + 10 + 16 * series.len() as i64 + 8;
        ring(&mut img, x1 + 21, ly + 3, 6, BLACK);
        draw_text(&mut img, x1 + 32, ly, "relume default", 1, BLACK);
    }
    let mut notes = Vec::new();
    if exact > 0 {
        notes.push(format!(
            "{exact} setting(s) with error 0 (exact) in the bottom row"
        ));
    }
    if skipped > 0 {
        notes.push(format!("{skipped} setting(s) not shown: no value"));
    }
    if !notes.is_empty() {
        draw_text(
            &mut img,
            LEFT,
            h - 20,
            &notes.join("; "),
            1,
            Rgb([90, 90, 90]),
        );
    }
    img
}

/// A square outline of half-side `r` around (x, y).
fn ring(img: &mut RgbImage, x: i64, y: i64, r: i64, c: Rgb<u8>) {
    line(img, (x - r, y - r), (x + r, y - r), c);
    line(img, (x + r, y - r), (x + r, y + r), c);
    line(img, (x + r, y + r), (x - r, y + r), c);
    line(img, (x - r, y + r), (x - r, y - r), c);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn axis_covers_whole_decades_and_ticks_label() {
        let a = Axis::covering([0.003, 0.2].into_iter());
        assert_eq!((a.lo, a.hi), (-3.0, 0.0));
        assert!((a.at(0.01) - 1.0 / 3.0).abs() < 1e-12);
        let one = Axis::covering([5.0].into_iter());
        assert_eq!((one.lo, one.hi), (0.0, 1.0));
        assert_eq!(tick_label(0.002), "2e-3");
        assert_eq!(tick_label(100.0), "100");
        assert_eq!(tick_label(5.0), "5");
    }

    #[test]
    fn the_default_is_ringed_and_exact_settings_get_the_zero_row() {
        use crate::study::{ErrorStats, Measure, Setting};
        let point = |label: &str, secs: f64, err: f64, default: bool| {
            let mut s = Setting::new(label, "a").default_if(default);
            s.seconds = secs;
            s.errors
                .insert("e".into(), ErrorStats::of(&[err], &[0.0], None));
            s
        };
        let spec = PlotSpec {
            file: "p.png".into(),
            title: "t".into(),
            x: Measure::Seconds,
            y: Measure::Error("e".into(), "mean".into()),
            x_label: "s".into(),
            y_label: "e".into(),
        };
        let sweep = |d: bool| Sweep {
            settings: vec![
                point("a", 0.01, 0.1, false),
                point("b", 0.1, 0.01, d),
                point("c", 1.0, 0.0, false),
            ],
            ..Default::default()
        };
        let (plain, ringed) = (draw(&spec, &sweep(false)), draw(&spec, &sweep(true)));
        // Only the ring (and the legend's "relume default" entry) differ.
        let differing: Vec<(u32, u32)> = plain
            .enumerate_pixels()
            .filter(|(x, y, p)| ringed.get_pixel(*x, *y) != *p)
            .map(|(x, y, _)| (x, y))
            .collect();
        assert!(!differing.is_empty());
        let in_plot: Vec<_> = differing
            .iter()
            .filter(|(x, _)| (*x as i64) < WIDTH as i64 - RIGHT)
            .collect();
        assert!(!in_plot.is_empty(), "the ring is drawn");
        // All inside a small box around point b (x = 0.1 s, the middle of the 1e-2..1 axis;
        // y = 1e-2, the bottom of the log axis, above the zero row).
        let cx = LEFT + (WIDTH as i64 - RIGHT - LEFT) / 2;
        let cy = HEIGHT as i64 - BOTTOM - 24;
        for (x, y) in in_plot {
            assert!(
                (*x as i64 - cx).abs() <= 12 && (*y as i64 - cy).abs() <= 12,
                "ring pixel at ({x}, {y}), point at ({cx}, {cy})"
            );
        }
        // The exact setting c sits in the zero row: its colour appears right above the frame.
        let row = HEIGHT as i64 - BOTTOM - 12;
        let cx = WIDTH as i64 - RIGHT;
        assert_eq!(*plain.get_pixel(cx as u32 - 1, row as u32), Rgb(PALETTE[0]));
    }

    #[test]
    fn every_font_glyph_is_five_columns_wide() {
        for (c, rows) in FONT {
            assert!(rows.iter().all(|r| *r < 0x20), "{c}");
        }
        assert_eq!(glyph('a'), glyph('A'));
        assert_eq!(glyph('€'), glyph('?'));
    }
}
