//! USD text as [`super::usda_check`] scans it: brackets, words, strings,
//! paths, asset paths and `=`, with their byte offsets; strings, comments and
//! path literals skipped as units, by the rules of the USD library's own
//! lexer (`#` comments end at `\n` or `\r`, `/* */` comments, strings that
//! span lines, escapes only in single-quoted strings), so that nothing the
//! library reads is hidden from the check.

use crate::error::{Error, FileFormat, Result};

fn malformed(reason: String) -> Error {
    Error::Malformed { format: FileFormat::Usd, reason }
}

/// One token of USD text that the check looks at.
#[derive(Debug, PartialEq)]
pub(super) enum Token<'a> {
    Open(u8),
    Close(u8),
    Word(&'a str),
    Text(&'a str),
    Path(&'a str),
    /// An asset path `@…@` (its text).
    Asset(&'a str),
    Equals,
}

/// The tokens of `text` with their byte offsets (strings, comments and paths
/// skipped as units); an unterminated string or path is an error.
pub(super) fn tokens(text: &str) -> Result<Vec<(usize, Token<'_>)>> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let unterminated = |at: usize, what: &str| malformed(format!("{} {what} that never ends", position(text, at)));
    while i < b.len() {
        let c = b[i];
        match c {
            // A comment ends at either line end, as the library's lexer has it.
            b'#' => i = b[i..].iter().position(|&c| c == b'\n' || c == b'\r').map_or(b.len(), |n| i + n),
            b'/' if b[i..].starts_with(b"/*") => {
                let end = b[i + 2..].windows(2).position(|w| w == b"*/").ok_or_else(|| unterminated(i, "a comment"))?;
                i += 2 + end + 2;
            }
            b'"' | b'\'' => {
                let triple = b[i..].starts_with(&[c, c, c]);
                let (start, quote) = if triple { (i + 3, 3) } else { (i + 1, 1) };
                let mut j = start;
                loop {
                    if j >= b.len() {
                        return Err(unterminated(i, "a string"));
                    }
                    // Escapes in a single-quoted string only (the library's triple
                    // quotes take every character but the closing three).
                    if b[j] == b'\\' && !triple {
                        j += 2;
                        continue;
                    }
                    if b[j] == c && (!triple || b[j..].starts_with(&[c, c, c])) {
                        break;
                    }
                    j += 1;
                }
                out.push((i, Token::Text(&text[start..j])));
                i = j + quote;
            }
            b'<' => {
                let end = b[i..].iter().position(|&c| c == b'>').ok_or_else(|| unterminated(i, "a path"))?;
                out.push((i, Token::Path(&text[i + 1..i + end])));
                i += end + 1;
            }
            b'@' => {
                let triple = b[i..].starts_with(b"@@@");
                let skip = if triple { 3 } else { 1 };
                let rest = &b[i + skip..];
                let end = if triple {
                    rest.windows(3).position(|w| w == b"@@@")
                } else {
                    rest.iter().position(|&c| c == b'@')
                }
                .ok_or_else(|| unterminated(i, "an asset path"))?;
                out.push((i, Token::Asset(&text[i + skip..i + skip + end])));
                i += skip + end + skip;
            }
            b'{' | b'(' | b'[' => {
                out.push((i, Token::Open(c)));
                i += 1;
            }
            b'}' | b')' | b']' => {
                out.push((i, Token::Close(c)));
                i += 1;
            }
            b'=' => {
                out.push((i, Token::Equals));
                i += 1;
            }
            c if c.is_ascii_alphabetic() || c == b'_' => {
                let end =
                    b[i..].iter().position(|&c| !(c.is_ascii_alphanumeric() || c == b'_' || c == b':' || c == b'.'));
                let end = end.map_or(b.len(), |n| i + n);
                out.push((i, Token::Word(&text[i..end])));
                i = end;
            }
            _ => i += 1,
        }
    }
    Ok(out)
}

/// "line L, column C:" of byte `at` of `text` (a line ends at `\n`, `\r\n`
/// or a lone `\r`).
pub fn position(text: &str, at: usize) -> String {
    let before = &text.as_bytes()[..at.min(text.len())];
    let ends = |k: usize| before[k] == b'\n' || (before[k] == b'\r' && before.get(k + 1) != Some(&b'\n'));
    let line = (0..before.len()).filter(|&k| ends(k)).count() + 1;
    let start = (0..before.len()).rev().find(|&k| ends(k)).map_or(0, |k| k + 1);
    format!("line {line}, column {}:", before.len() - start + 1)
}
