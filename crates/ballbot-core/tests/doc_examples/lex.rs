//! Lexing: a copy of the source with comments and the contents of string and char literals
//! blanked (newlines kept), so braces and keywords can be counted without being fooled.

pub(super) fn is_ident_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Appends `c` blanked: newlines stay, everything else becomes a space.
pub(super) fn blank(out: &mut String, c: char) {
    out.push(if c == '\n' { '\n' } else { ' ' });
}

pub(super) fn code_view(source: &str) -> String {
    let b: Vec<char> = source.chars().collect();
    let n = b.len();
    let mut out = String::with_capacity(source.len());
    let mut i = 0;
    while i < n {
        let c = b[i];
        let next = b.get(i + 1).copied();
        let prev = if i > 0 { Some(b[i - 1]) } else { None };
        if c == '/' && next == Some('/') {
            while i < n && b[i] != '\n' {
                blank(&mut out, b[i]);
                i += 1;
            }
            continue;
        }
        if c == '/' && next == Some('*') {
            let mut depth = 0usize;
            while i < n {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    blank(&mut out, b[i]);
                    blank(&mut out, b[i + 1]);
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    blank(&mut out, b[i]);
                    blank(&mut out, b[i + 1]);
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    blank(&mut out, b[i]);
                    i += 1;
                }
            }
            continue;
        }
        // Raw strings r"..", r#".."#, br"..": the `r` must start a token (or follow a `b` that
        // does); `r#ident` (a raw identifier) has no quote after the hashes.
        let starts_token = |k: usize| k == 0 || !is_ident_char(b[k - 1]);
        if c == 'r'
            && (starts_token(i) || (prev == Some('b') && starts_token(i - 1)))
            && matches!(next, Some('"') | Some('#'))
        {
            let mut j = i + 1;
            while j < n && b[j] == '#' {
                j += 1;
            }
            if j < n && b[j] == '"' {
                let hashes = j - i - 1;
                for &ch in &b[i..=j] {
                    out.push(ch);
                }
                i = j + 1;
                while i < n {
                    if b[i] == '"'
                        && b[i + 1..]
                            .iter()
                            .take(hashes)
                            .filter(|&&h| h == '#')
                            .count()
                            == hashes
                    {
                        for &ch in &b[i..=i + hashes] {
                            out.push(ch);
                        }
                        i += hashes + 1;
                        break;
                    }
                    blank(&mut out, b[i]);
                    i += 1;
                }
                continue;
            }
        }
        if c == '"' {
            i = quoted(&b, i, '"', &mut out);
            continue;
        }
        if c == '\'' {
            // A char literal ('x', '\n', '\u{..}') or a lifetime ('a).
            if next == Some('\\') {
                i = quoted(&b, i, '\'', &mut out);
                continue;
            }
            if b.get(i + 2) == Some(&'\'') {
                out.push('\'');
                blank(&mut out, b[i + 1]);
                out.push('\'');
                i += 3;
                continue;
            }
        }
        out.push(c);
        i += 1;
    }
    out
}

/// Copies the quoted literal that opens at `b[start] == quote` with its contents blanked
/// (escapes `\x` included) and returns the index after the closing quote.
fn quoted(b: &[char], start: usize, quote: char, out: &mut String) -> usize {
    let n = b.len();
    out.push(quote);
    let mut i = start + 1;
    while i < n {
        if b[i] == '\\' && i + 1 < n {
            blank(out, b[i]);
            blank(out, b[i + 1]);
            i += 2;
        } else if b[i] == quote {
            out.push(quote);
            return i + 1;
        } else {
            blank(out, b[i]);
            i += 1;
        }
    }
    i
}
