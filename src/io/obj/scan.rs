//! Finding the line behind an OBJ error. tobj says what is wrong but not where, and it
//! renumbers vertices, so when it fails (or returns a non-finite value) the source is scanned
//! again here, applying tobj's rules, to name the offending line. This runs only on the error
//! path, so it favours simplicity over speed.

use crate::io::{assemble, text};
use glam::DVec3;
use std::str::SplitWhitespace;

/// Data a face corner `v/vt/vn` refers to; the value is the part's position in the corner
/// (1, texture coordinates, is never asked for).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Data {
    Position = 0,
    Normal = 2,
}

const KEYWORDS: [&str; 3] = ["v", "vt", "vn"];
const NAMES: [&str; 3] = ["vertex", "texture coordinate", "normal"];

/// Numbers of `v`, `vt` and `vn` lines.
type Counts = [usize; 3];

/// The first line tobj would reject, as `(line, what is wrong)`.
pub(super) fn first_malformed(source: &str) -> Option<(usize, String)> {
    let totals = totals(source);
    let mut seen = [0; 3];
    // The faces of the object being read, each with its line and its largest index of each
    // kind: tobj checks them against the lines read when the object ends.
    let mut faces: Vec<(usize, [Option<usize>; 3])> = Vec::new();
    for (n, line) in text::lines(source.as_bytes()) {
        let mut words = line.split_whitespace();
        let keyword = words.next();
        let checked = match keyword {
            Some("v") => position(words),
            Some("vt") => numbers::<2>(&mut words).map(drop),
            Some("vn") => numbers::<3>(&mut words).map(drop),
            Some("f") => corners(words, &seen, &totals).map(|c| faces.extend(largest(&c).map(|l| (n, l)))),
            Some("l") => corners(words, &seen, &totals).map(drop),
            Some("usemtl") if words.next().is_none() => Err("`usemtl` without a material name".into()),
            _ => Ok(()),
        };
        if let Err(message) = checked {
            return Some((n, message));
        }
        if matches!(keyword, Some("o" | "g")) {
            if let Some(found) = ahead_of_object(&faces, &seen, n) {
                return Some(found);
            }
            faces.clear();
        }
        if let Some(k) = KEYWORDS.iter().position(|k| Some(*k) == keyword) {
            seen[k] += 1;
        }
    }
    None
}

/// The largest index of each kind among `corners`; `None` for a face without corners.
fn largest(corners: &[[Option<usize>; 3]]) -> Option<[Option<usize>; 3]> {
    let first = *corners.first()?;
    Some(corners.iter().fold(first, |most, corner| std::array::from_fn(|k| most[k].max(corner[k]))))
}

/// The first of `faces` (of an object that ends at line `end`, after `seen` lines of each
/// kind) that uses a line after the object's end: tobj refuses it, although the file has it.
fn ahead_of_object(faces: &[(usize, [Option<usize>; 3])], seen: &Counts, end: usize) -> Option<(usize, String)> {
    faces.iter().find_map(|(line, most)| {
        (0..3).find_map(|k| {
            let index = most[k].filter(|&i| i >= seen[k])? + 1;
            let (name, keyword, before) = (NAMES[k], KEYWORDS[k], seen[k]);
            Some((
                *line,
                format!(
                    "{name} index {index} is out of range: its object ends at line {end} after {before} `{keyword}` \
                     lines, and a face may only use those"
                ),
            ))
        })
    })
}

/// `source` with the colours of its `v x y z r g b` lines dropped, every line where it was.
pub(super) fn without_colours(source: &str) -> String {
    let mut kept = String::with_capacity(source.len());
    for line in source.split_inclusive('\n') {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words[..] {
            ["v", x, y, z, _, _, _] => kept.push_str(&format!("v {x} {y} {z}\n")),
            _ => kept.push_str(line),
        }
    }
    kept
}

/// The first `f` line with fewer than three corners, as `(line, what is wrong)`: tobj drops
/// such faces without a word, where PLY and OFF readers refuse them.
pub(super) fn first_short_face(source: &str) -> Option<(usize, String)> {
    text::lines(source.as_bytes()).find_map(|(n, line)| {
        let mut words = line.split_whitespace();
        if words.next() != Some("f") {
            return None;
        }
        let corners = words.take_while(|w| !w.starts_with('#')).count();
        (corners < 3).then(|| {
            let plural = if corners == 1 { "" } else { "s" };
            (n, format!("a face with {corners} corner{plural}: a face needs at least 3 (a line is written with `l`)"))
        })
    })
}

/// The `v` (or `vn`) line of the first non-finite position (or normal) that a face uses, as
/// `(line, what is wrong)`. Unused values are not reported: tobj drops them.
pub(super) fn first_non_finite_use(source: &str, data: Data) -> Option<(usize, String)> {
    let k = data as usize;
    // For each value: its line, and what is wrong with it, if anything.
    let mut values: Vec<(usize, Option<String>)> = Vec::new();
    for (n, line) in text::lines(source.as_bytes()) {
        let mut words = line.split_whitespace();
        if words.next() != Some(KEYWORDS[k]) {
            continue;
        }
        let problem = numbers::<3>(&mut words).ok().and_then(|xyz| {
            let v = DVec3::from(xyz);
            let finite = if data == Data::Normal {
                assemble::finite_normal(v.as_vec3()).map(drop)
            } else {
                assemble::finite_position(v).map(drop)
            };
            finite.err().map(|m| format!("{} {} {m}", NAMES[k], values.len()))
        });
        values.push((n, problem));
    }
    let totals = totals(source);
    let mut seen = [0; 3];
    for (_, line) in text::lines(source.as_bytes()) {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("f" | "l") => {
                for corner in corners(words, &seen, &totals).unwrap_or_default() {
                    if let Some((n, Some(problem))) = corner[k].and_then(|i| values.get(i)) {
                        return Some((*n, problem.clone()));
                    }
                }
            }
            Some(keyword) => {
                if let Some(k) = KEYWORDS.iter().position(|k| *k == keyword) {
                    seen[k] += 1;
                }
            }
            None => {}
        }
    }
    None
}

fn totals(source: &str) -> Counts {
    let mut totals = [0; 3];
    for (_, line) in text::lines(source.as_bytes()) {
        if let Some(k) = line.split_whitespace().next().and_then(|w| KEYWORDS.iter().position(|k| *k == w)) {
            totals[k] += 1;
        }
    }
    totals
}

/// The first `N` numbers of a line; more are ignored, as tobj does.
fn numbers<const N: usize>(words: &mut SplitWhitespace) -> Result<[f64; N], String> {
    let mut values = [0.0; N];
    for (found, value) in values.iter_mut().enumerate() {
        let word = words.next().ok_or_else(|| format!("expected {N} numbers, found {found}"))?;
        *value = text::number(word)?;
    }
    Ok(values)
}

/// `v x y z`, optionally followed by a weight `w` (not 0) or a color `r g b`.
fn position(mut words: SplitWhitespace) -> Result<(), String> {
    numbers::<3>(&mut words)?;
    let rest: Vec<&str> = words.collect();
    match rest[..] {
        [] | [_, _, _] => Ok(()),
        [w] => match text::number::<f64>(w)? {
            0.0 => Err("the weight w is 0".into()),
            _ => Ok(()),
        },
        _ => Err(format!("expected x y z, x y z w or x y z r g b, found {} numbers", 3 + rest.len())),
    }
}

/// The corners of an `f` (or `l`) line as indices from 0 into the `v`, `vt` and `vn` lines.
/// `seen` counts the lines before this one (for relative indices), `totals` those in the file.
/// Lines with one or two corners are points and lines: tobj ignores them, so their indices
/// are not checked and no corners are returned.
fn corners(words: SplitWhitespace, seen: &Counts, totals: &Counts) -> Result<Vec<[Option<usize>; 3]>, String> {
    let raw = words.map(corner).collect::<Result<Vec<_>, _>>()?;
    match raw.len() {
        0 => Err("face without vertices".into()),
        1 | 2 => Ok(Vec::new()),
        _ => raw.iter().map(|c| resolve(c, seen, totals)).collect(),
    }
}

/// The parts of one corner `v`, `v/vt`, `v//vn` or `v/vt/vn`, as written.
fn corner(word: &str) -> Result<[Option<isize>; 3], String> {
    let mut parts = [None; 3];
    for (k, part) in word.split('/').enumerate().filter(|(_, part)| !part.is_empty()) {
        let slot = parts.get_mut(k).ok_or_else(|| format!("corner {} has more than 3 parts", text::quoted(word)))?;
        let index = part
            .parse()
            .map_err(|_| format!("corner {}: expected an index, found {}", text::quoted(word), text::quoted(part)))?;
        *slot = Some(index);
    }
    Ok(parts)
}

/// Checks a corner's indices and makes them absolute. Texture coordinate and normal indices
/// are checked only when the file has any of them: tobj ignores them otherwise.
fn resolve(parts: &[Option<isize>; 3], seen: &Counts, totals: &Counts) -> Result<[Option<usize>; 3], String> {
    let mut resolved = [None; 3];
    for (k, slot) in resolved.iter_mut().enumerate() {
        *slot = match parts[k] {
            None if k == 0 => return Err("a corner has no vertex index".into()),
            Some(index) if k == 0 || totals[k] > 0 => Some(absolute(index, k, seen[k], totals[k])?),
            _ => None,
        };
    }
    Ok(resolved)
}

/// Index `index` (from 1, or negative for relative to the `seen` lines before) of a `total`
/// lines long list. tobj checks positive indices against the lines read by the end of the
/// object; the file's total is used here, which differs only for forward references.
fn absolute(index: isize, k: usize, seen: usize, total: usize) -> Result<usize, String> {
    let (name, keyword) = (NAMES[k], KEYWORDS[k]);
    if index == 0 {
        return Err(format!("{name} index 0 is invalid: indices start at 1"));
    }
    match usize::try_from(index) {
        Ok(from_one) if from_one <= total => Ok(from_one - 1),
        Ok(_) => Err(format!("{name} index {index} is out of range: the file has {total} `{keyword}` lines")),
        Err(_) => seen.checked_sub(index.unsigned_abs()).ok_or_else(|| {
            format!("relative {name} index {index} is out of range: only {seen} `{keyword}` lines precede it")
        }),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(source: &str) -> Option<(usize, String)> {
        first_malformed(source)
    }

    #[test]
    fn finds_malformed_lines() {
        let good = "v 0 0 0\nv 1 0 0 1\nv 0 1 0 1 0 0\nvt 0 0\nvn 0 0 1\nf 1/1/1 2//1 -1\nl 1 9\nf 5\n";
        assert_eq!(at(good), None);
        let (n, m) = at("v 0 0 0\nv 1 x 0\n").unwrap();
        assert!(n == 2 && m.contains("`x`"), "{n} {m}");
        let (n, m) = at("v 0 0\n").unwrap();
        assert!(n == 1 && m.contains("expected 3 numbers, found 2"), "{n} {m}");
        assert!(at("v 0 0 0 0\n").unwrap().1.contains("w is 0"));
        assert!(at("v 0 0 0 1 1\n").unwrap().1.contains("found 5 numbers"));
        assert_eq!(at("vn 0 0\n").map(|e| e.0), Some(1));
    }

    #[test]
    fn finds_bad_face_indices() {
        let tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
        let (n, m) = at(&format!("{tri}f 1 2 4\n")).unwrap();
        assert!(n == 4 && m.contains("vertex index 4") && m.contains("3 `v` lines"), "{n} {m}");
        let (n, m) = at(&format!("{tri}f 0 1 2\n")).unwrap();
        assert!(n == 4 && m.contains("index 0"), "{n} {m}");
        let (n, m) = at(&format!("v 0 0 0\nf -1 -2 -1\n{tri}")).unwrap();
        assert!(n == 2 && m.contains("relative vertex index -2") && m.contains("only 1"), "{n} {m}");
        let (n, m) = at(&format!("{tri}vn 0 0 1\nf 1//1 2//2 3//1\n")).unwrap();
        assert!(n == 5 && m.contains("normal index 2"), "{n} {m}");
        assert!(at(&format!("{tri}f 1/a 2 3\n")).unwrap().1.contains("`a`"));
        assert!(at(&format!("{tri}f 1/1/1/1 2 3\n")).unwrap().1.contains("more than 3 parts"));
        assert!(at(&format!("{tri}f\n")).unwrap().1.contains("without vertices"));
        assert!(at(&format!("{tri}f 1 2 -9223372036854775808\n")).is_some());
        // Indices of points and lines are never checked, and vt is ignored without `vt` lines.
        assert_eq!(at(&format!("{tri}f 1 9\nf 1/7 2/8 3/9\n")), None);
    }

    #[test]
    fn finds_the_line_of_a_used_non_finite_value() {
        let src = "v nan 0 0\nv 0 0 0\nv inf 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nvn 0 nan 1\nf 2//1 3//2 4//1\n";
        let (n, m) = first_non_finite_use(src, Data::Position).unwrap();
        assert!(n == 3 && m.contains("vertex 2 has a NaN or infinite coordinate"), "{n} {m}");
        let (n, m) = first_non_finite_use(src, Data::Normal).unwrap();
        assert!(n == 7 && m.contains("normal 1"), "{n} {m}");
        assert_eq!(first_non_finite_use("v nan 0 0\nv 0 0 0\nf 2 2 2\n", Data::Position), None);
    }
}
