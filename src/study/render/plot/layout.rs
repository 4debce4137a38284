//! Layout decisions of every figure, made before plotters draws: tick positions and their
//! labels, the title's size and line breaks, where the legend goes, and the text plotters is
//! given (XML-safe). All of it works from the same text-size estimate, so that a figure's
//! labels can be checked against the canvas by counting characters (tests/studies/figures.rs).

/// The width of `text` at `pt` in pixels, as laid out here: 0.6 em per character, where an
/// em is the SVG font size plotters writes (`pt / 1.24`). Sans-serif faces average about
/// 0.55 em per character, so this errs towards more room; plotters' own estimate (0.7 em of
/// `pt / 1.24²` per byte) is smaller for ASCII, and is what sizes its legend boxes.
pub(crate) fn text_width(text: &str, pt: u32) -> f64 {
    0.6 * em(pt) * text.chars().count() as f64
}

/// The SVG font size of a plotters font of `pt`, in pixels.
pub(crate) fn em(pt: u32) -> f64 {
    pt as f64 / 1.24
}

/// Text as plotters may write it into SVG: control characters (which no XML parser reads,
/// escaped or not) become spaces; plotters itself escapes `<`, `>`, `&` and quotes.
pub(crate) fn svg_text(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// An axis's ticks: the values plotters marks and the label of each.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Ticks {
    pub values: Vec<f64>,
    pub labels: Vec<String>,
}

impl Ticks {
    /// The label of the tick at `v` (plotters hands back the values it was given).
    pub fn label(&self, v: f64) -> String {
        self.values
            .iter()
            .position(|&t| t == v)
            .map_or_else(String::new, |i| self.labels[i].clone())
    }
}

/// The most labels an axis carries: more are unreadable at the figure's size.
const MAX_TICKS: usize = 9;
/// The least gap between two tick labels, in pixels.
const TICK_GAP: f64 = 8.0;

/// Ticks of the axis from `lo` to `hi` drawn over `pixels` (horizontal: labels side by side,
/// else stacked), labels in `pt`: a candidate set whose labels fit without overlap, at most
/// [`MAX_TICKS`] and at least two. A linear axis takes the densest. A log axis is labelled at
/// powers of ten (every one, or every second or third when there are many), else at 1, 2 and
/// 5 per decade, else at every digit, else (a range under a decade) at round linear steps
/// ("minor" labels), the first of these with three labels: at least two however short its
/// range.
pub(crate) fn ticks(lo: f64, hi: f64, log: bool, pixels: f64, horizontal: bool, pt: u32) -> Ticks {
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let at = |v: f64| {
        if log {
            (v / lo).ln() / (hi / lo).ln() * pixels
        } else {
            (v - lo) / (hi - lo) * pixels
        }
    };
    let fits = |t: &Ticks| {
        t.values.windows(2).zip(t.labels.windows(2)).all(|(v, l)| {
            let room = (at(v[1]) - at(v[0])).abs();
            let need = if horizontal {
                0.5 * (text_width(&l[0], pt) + text_width(&l[1], pt))
            } else {
                em(pt)
            };
            room >= need + TICK_GAP
        })
    };
    let candidates: Vec<Ticks> = if log && lo > 0.0 && hi > lo {
        log_candidates(lo, hi)
    } else if hi > lo {
        linear_candidates(lo, hi)
    } else {
        vec![]
    }
    .into_iter()
    .map(|values| Ticks {
        labels: labels(&values),
        values,
    })
    .collect();
    let usable = |t: &&Ticks| t.values.len() >= 2 && t.values.len() <= MAX_TICKS;
    // A log axis takes the first set, in the order above, with three labels or more (two if
    // none has three); a linear axis the densest.
    let chosen = if log {
        let first = |least: usize| {
            candidates
                .iter()
                .filter(usable)
                .find(|t| t.values.len() >= least && fits(t))
        };
        first(3).or_else(|| first(2))
    } else {
        candidates
            .iter()
            .filter(usable)
            .filter(|t| fits(t))
            .max_by_key(|t| t.values.len())
    };
    chosen
        .or_else(|| candidates.iter().filter(usable).min_by_key(|t| t.values.len()))
        .cloned()
        .unwrap_or_else(|| {
            let values = if hi > lo { vec![lo, hi] } else { vec![lo] };
            Ticks {
                labels: labels(&values),
                values,
            }
        })
}

/// Multiples of round steps (1, 2, 2.5 and 5 times a power of ten) within [lo, hi], one set
/// per step, coarsest first.
fn linear_candidates(lo: f64, hi: f64) -> Vec<Vec<f64>> {
    let span = hi - lo;
    let top = span.log10().floor() as i32 + 1;
    let mut out = vec![];
    for k in (top - 3..=top).rev() {
        for m in [5.0, 2.5, 2.0, 1.0] {
            let step = m * 10f64.powi(k);
            let (a, b) = ((lo / step).ceil() as i64, (hi / step).floor() as i64);
            if b - a > 40 {
                continue;
            }
            let values: Vec<f64> = (a..=b)
                .map(|i| {
                    let v = i as f64 * step;
                    // A tick at zero is zero, not a rounding residue of the step.
                    if v.abs() < 1e-9 * step {
                        0.0
                    } else {
                        v
                    }
                })
                .collect();
            if !values.is_empty() {
                out.push(values);
            }
        }
    }
    out
}

fn log_candidates(lo: f64, hi: f64) -> Vec<Vec<f64>> {
    let (k0, k1) = (lo.log10().floor() as i32, hi.log10().ceil() as i32);
    let within = |v: &f64| *v >= lo * (1.0 - 1e-12) && *v <= hi * (1.0 + 1e-12);
    let decades = |every: i32| -> Vec<f64> {
        (k0..=k1)
            .filter(|k| k.rem_euclid(every) == 0)
            .map(|k| 10f64.powi(k))
            .filter(within)
            .collect()
    };
    let mantissas = |ms: &[f64]| -> Vec<f64> {
        (k0..=k1)
            .flat_map(|k| ms.iter().map(move |m| m * 10f64.powi(k)))
            .filter(within)
            .collect()
    };
    let mut out = vec![decades(1), decades(2), decades(3)];
    out.push(mantissas(&[1.0, 2.0, 5.0]));
    out.push(mantissas(&[1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]));
    if hi / lo < 10.0 {
        out.extend(
            linear_candidates(lo, hi)
                .into_iter()
                .filter(|v| v.iter().all(|&x| x > 0.0)),
        );
    }
    out
}

/// Labels of tick values: plain decimals (or, when a tick is under 1e-3 or from 1e5 up,
/// mantissa-exponent), with the fewest digits that tell every tick apart and give each
/// value back.
pub(crate) fn labels(values: &[f64]) -> Vec<String> {
    let sci = values
        .iter()
        .any(|v| *v != 0.0 && (v.abs() < 1e-3 || v.abs() >= 1e5));
    let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    for digits in 0..=12 {
        let out: Vec<String> = values.iter().map(|&v| number(v, digits, sci)).collect();
        let exact = out.iter().zip(values).all(|(s, v)| {
            let back: f64 = s.parse().unwrap_or(f64::NAN);
            (back - v).abs() <= 1e-9 * scale.max(v.abs()) || (sci && (back / v - 1.0).abs() < 1e-9)
        });
        let distinct = out.iter().enumerate().all(|(i, a)| !out[..i].contains(a));
        if exact && distinct {
            return out;
        }
    }
    values.iter().map(|v| format!("{v}")).collect()
}

fn number(v: f64, digits: usize, sci: bool) -> String {
    if v == 0.0 {
        return "0".into();
    }
    if sci {
        let s = format!("{v:.digits$e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = if m.contains('.') {
            m.trim_end_matches('0').trim_end_matches('.')
        } else {
            m
        };
        format!("{m}e{e}")
    } else {
        let s = format!("{v:.digits$}");
        let s = if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        };
        if s == "-0" {
            "0".into()
        } else {
            s
        }
    }
}

/// A title broken into lines at `pt`, each fitting `width` pixels.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct TitleLayout {
    pub pt: u32,
    pub lines: Vec<String>,
}

impl TitleLayout {
    /// The height the title takes, margins included.
    pub fn height(&self) -> u32 {
        if self.lines.is_empty() {
            return 10;
        }
        (8.0 + self.lines.len() as f64 * 1.25 * self.pt as f64).ceil() as u32
    }
}

/// `title` at the largest size from `pt` down that fits `width` on one line (down to 4/5 of
/// `pt`), else on two, three or more lines (down to 2/3 of `pt`); words longer than a line
/// are broken between characters.
pub(crate) fn title_layout(title: &str, pt: u32, width: f64) -> TitleLayout {
    let title = svg_text(title);
    let words: Vec<&str> = title.split_whitespace().collect();
    if words.is_empty() {
        return TitleLayout { pt, lines: vec![] };
    }
    let smallest = (2 * pt).div_ceil(3);
    for lines in 1..=6usize {
        let floor = if lines == 1 {
            (4 * pt).div_ceil(5)
        } else {
            smallest
        };
        for size in (floor..=pt).rev() {
            let wrapped = wrap(&words, width, size);
            if wrapped.len() <= lines {
                return TitleLayout {
                    pt: size,
                    lines: wrapped,
                };
            }
        }
    }
    TitleLayout {
        pt: smallest,
        lines: wrap(&words, width, smallest),
    }
}

/// Greedy line filling: as many words per line as fit in `width` at `pt`.
fn wrap(words: &[&str], width: f64, pt: u32) -> Vec<String> {
    let mut lines: Vec<String> = vec![];
    let mut line = String::new();
    for w in words {
        let candidate = if line.is_empty() {
            w.to_string()
        } else {
            format!("{line} {w}")
        };
        if text_width(&candidate, pt) <= width {
            line = candidate;
            continue;
        }
        if !line.is_empty() {
            lines.push(std::mem::take(&mut line));
        }
        // A word alone too long for a line: cut it between characters.
        let mut rest = String::new();
        for c in w.chars() {
            rest.push(c);
            if text_width(&rest, pt) > width {
                let last = rest.pop().unwrap_or(' ');
                lines.push(std::mem::take(&mut rest));
                rest.push(last);
            }
        }
        line = rest;
    }
    if !line.is_empty() {
        lines.push(line);
    }
    lines
}

/// Where `v` falls on the axis from `lo` to `hi` as a fraction of its length.
pub(crate) fn fraction(v: f64, lo: f64, hi: f64, log: bool) -> f64 {
    if log {
        (v / lo).ln() / (hi / lo).ln()
    } else {
        (v - lo) / (hi - lo)
    }
}

/// The value at fraction `f` of the axis from `lo` to `hi` (the inverse of [`fraction`]).
pub(crate) fn at_fraction(f: f64, lo: f64, hi: f64, log: bool) -> f64 {
    if log {
        lo * (hi / lo).powf(f)
    } else {
        lo + f * (hi - lo)
    }
}

/// A legend corner inside the plot.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Corner {
    UpperLeft,
    UpperRight,
    LowerLeft,
    LowerRight,
}

/// The size of plotters' legend box of `labels` at `pt` in pixels, by its own estimate (label
/// width 0.7 em of `pt / 1.24²` per byte, lines 1.25 `pt` apart, margins of 12 around and 30
/// for the symbol), plus a few pixels of slack.
pub(crate) fn legend_size(labels: &[String], pt: u32) -> (f64, f64) {
    if labels.is_empty() {
        return (0.0, 0.0);
    }
    let em = pt as f64 / 1.24 / 1.24;
    let w = labels
        .iter()
        .map(|l| (em * 0.7 * l.len() as f64).round())
        .fold(0.0, f64::max);
    let h = (labels.len() - 1) as f64 * 1.25 * pt as f64 + em.round() + (0.24 * em).round();
    (w + 30.0 + 24.0 + 4.0, h + 24.0 + 4.0)
}

/// Where the legend goes: a corner whose box covers no data, `preferred` first. Data are
/// given in plot fractions (x from the left, y from the bottom, each in [0, 1]): points, and
/// polylines whose segments count too; markers are taken to reach 7 pixels around a point.
/// When every corner covers data, the y range is extended (by a fraction of the plot height)
/// at the top or at the bottom, whichever needs less, so that the legend has a band of its
/// own: the result is the corner and the new y range in fractions of the old (e.g. (0, 1.4)).
pub(crate) fn place_legend(
    points: &[(f64, f64)],
    lines: &[Vec<(f64, f64)>],
    legend: (f64, f64),
    plot: (f64, f64),
    preferred: Corner,
) -> (Corner, (f64, f64)) {
    let (w, h) = plot;
    let pad = 7.0;
    let boxed = |c: Corner| -> [f64; 4] {
        // Pixels from the plot's left and top edge, as plotters lays the legend out.
        let x0 = match c {
            Corner::UpperLeft | Corner::LowerLeft => 5.0,
            _ => w - legend.0 - 5.0,
        };
        let y0 = match c {
            Corner::UpperLeft | Corner::UpperRight => 5.0,
            _ => h - legend.1 - 5.0,
        };
        [x0 - pad, y0 - pad, x0 + legend.0 + pad, y0 + legend.1 + pad]
    };
    let px = |p: &(f64, f64)| (p.0 * w, (1.0 - p.1) * h);
    let inside = |b: &[f64; 4], q: (f64, f64)| q.0 >= b[0] && q.0 <= b[2] && q.1 >= b[1] && q.1 <= b[3];
    let free = |c: Corner| {
        let b = boxed(c);
        !points.iter().any(|p| inside(&b, px(p)))
            && !lines.iter().any(|l| {
                l.windows(2).any(|s| {
                    let (a, z) = (px(&s[0]), px(&s[1]));
                    let n = ((z.0 - a.0).hypot(z.1 - a.1) / 3.0).ceil().clamp(1.0, 2000.0) as usize;
                    (0..=n).any(|k| {
                        let t = k as f64 / n as f64;
                        inside(&b, (a.0 + t * (z.0 - a.0), a.1 + t * (z.1 - a.1)))
                    })
                })
            })
    };
    let order = [
        preferred,
        Corner::UpperRight,
        Corner::UpperLeft,
        Corner::LowerRight,
        Corner::LowerLeft,
    ];
    if let Some(&c) = order.iter().find(|&&c| free(c)) {
        return (c, (0.0, 1.0));
    }
    // A band of the legend's height (and its margins) above or below every datum.
    let ys = points.iter().chain(lines.iter().flatten()).map(|p| p.1);
    let (lo, hi) = ys.fold((1.0f64, 0.0f64), |(a, b), y| (a.min(y), b.max(y)));
    let band = (legend.1 + 5.0 + 2.0 * pad) / h;
    // With the range stretched by s, the data's fractions shrink by 1/s: the top (bottom)
    // band is free when hi / s <= 1 - band (lo moved up past it).
    let s_top = (hi / (1.0 - band)).max(1.0);
    let s_bottom = ((1.0 - lo) / (1.0 - band)).max(1.0);
    let upper = matches!(preferred, Corner::UpperLeft | Corner::UpperRight);
    let left = matches!(preferred, Corner::UpperLeft | Corner::LowerLeft);
    if s_top < s_bottom || (s_top == s_bottom && upper) {
        let c = if left {
            Corner::UpperLeft
        } else {
            Corner::UpperRight
        };
        (c, (0.0, s_top))
    } else {
        let c = if left {
            Corner::LowerLeft
        } else {
            Corner::LowerRight
        };
        (c, (1.0 - s_bottom, 1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The axes of the duplicated-tick reports (issue 45): a log axis from 0.08 to 1.6 and one
    /// from 3 to 200 label each value once; an axis spanning under a decade has at least two
    /// labels.
    #[test]
    fn log_ticks_are_distinct_and_at_least_two() {
        for (lo, hi) in [(0.08, 1.6), (3.0, 200.0), (0.9, 1.5), (20.0, 35.0), (1e-6, 0.2)] {
            let t = ticks(lo, hi, true, 750.0, true, 16);
            assert!(t.values.len() >= 2, "{lo}..{hi}: {t:?}");
            for (i, l) in t.labels.iter().enumerate() {
                assert!(!t.labels[..i].contains(l), "{lo}..{hi}: {t:?}");
            }
            assert!(t.values.iter().all(|&v| v >= lo && v <= hi), "{t:?}");
        }
    }

    #[test]
    fn labels_use_the_fewest_digits() {
        assert_eq!(labels(&[0.975, 0.98, 0.985]), ["0.975", "0.98", "0.985"]);
        assert_eq!(labels(&[1e-6, 1e-4, 1e-2]), ["1e-6", "1e-4", "1e-2"]);
        assert_eq!(labels(&[-1.0, -0.5, 0.0, 0.5]), ["-1", "-0.5", "0", "0.5"]);
        assert_eq!(labels(&[2e-4, 5e-4]), ["2e-4", "5e-4"]);
    }

    #[test]
    fn titles_fit_their_width() {
        let long = "Initial (grey) and final domains next to the symmetry plane y = 0, coloured by σzz, elastic, h = 1, 2x2x2 points per cell";
        let t = title_layout(long, 24, 860.0);
        assert!(t.lines.len() >= 2, "{t:?}");
        assert!(t.lines.iter().all(|l| text_width(l, t.pt) <= 860.0), "{t:?}");
        assert_eq!(t.lines.join(" "), long);
        let short = title_layout("Figure 8", 24, 860.0);
        assert_eq!((short.pt, short.lines.len()), (24, 1));
        let word = title_layout(&"x".repeat(300), 24, 300.0);
        assert!(
            word.lines.iter().all(|l| text_width(l, word.pt) <= 300.0),
            "{word:?}"
        );
        assert_eq!(svg_text("a\u{7}b\nc"), "a b c");
    }
}
