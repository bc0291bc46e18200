//! A tiny XML well-formedness checker for the plot tests (no XML crate needed): balanced tags,
//! one root, quoted unique attributes, escaped text.

/// Checks `doc` is well-formed XML as far as these plots use it: optional declaration, comments,
/// one root element, balanced tags, valid names, quoted unique attributes, and no raw `<`, `>` or
/// stray `&` in text or attribute values. Returns the number of elements.
pub(super) fn check_well_formed(doc: &str) -> Result<usize, String> {
    let mut rest = doc.strip_prefix("<?xml").map_or(Ok(doc), |r| {
        r.find("?>")
            .map(|e| &r[e + 2..])
            .ok_or("unterminated declaration")
    })?;
    let (mut stack, mut elements, mut roots) = (Vec::new(), 0, 0);
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix("<!--") {
            let end = r.find("-->").ok_or("unterminated comment")?;
            if r[..end].contains("--") || r[..end].ends_with('-') {
                return Err("'--' inside a comment".into());
            }
            rest = &r[end + 3..];
        } else if let Some(r) = rest.strip_prefix("</") {
            let end = r.find('>').ok_or("unterminated end tag")?;
            let name = r[..end].trim_end();
            match stack.pop() {
                Some(open) if open == name => {}
                other => return Err(format!("</{name}> closes {other:?}")),
            }
            rest = &r[end + 1..];
        } else if let Some(r) = rest.strip_prefix('<') {
            let end = r.find('>').ok_or("unterminated tag")?;
            let (body, empty) = match r[..end].strip_suffix('/') {
                Some(b) => (b, true),
                None => (&r[..end], false),
            };
            let name_end = body.find(char::is_whitespace).unwrap_or(body.len());
            let name = &body[..name_end];
            check_name(name)?;
            check_attributes(&body[name_end..])?;
            if stack.is_empty() {
                roots += 1;
            }
            elements += 1;
            if !empty {
                stack.push(name);
            }
            rest = &r[end + 1..];
        } else {
            let end = rest.find('<').unwrap_or(rest.len());
            let text = &rest[..end];
            if stack.is_empty() && !text.trim().is_empty() {
                return Err(format!("text outside the root: {text:?}"));
            }
            check_escaped(text)?;
            rest = &rest[end..];
        }
    }
    match (stack.last(), roots) {
        (Some(open), _) => Err(format!("<{open}> never closed")),
        (None, 1) => Ok(elements),
        (None, n) => Err(format!("{n} root elements")),
    }
}

fn check_name(name: &str) -> Result<(), String> {
    let mut chars = name.chars();
    let first_ok = chars
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_');
    if first_ok && chars.all(|c| c.is_ascii_alphanumeric() || "-_:.".contains(c)) {
        Ok(())
    } else {
        Err(format!("bad name {name:?}"))
    }
}

fn check_attributes(mut s: &str) -> Result<(), String> {
    let mut seen = Vec::new();
    loop {
        let trimmed = s.trim_start();
        if trimmed.is_empty() {
            return Ok(());
        }
        if trimmed.len() == s.len() {
            return Err(format!("no space before attribute: {s:?}"));
        }
        let eq = trimmed
            .find("=\"")
            .ok_or(format!("unquoted attribute: {trimmed:?}"))?;
        let name = &trimmed[..eq];
        check_name(name)?;
        if seen.contains(&name) {
            return Err(format!("duplicate attribute {name}"));
        }
        seen.push(name);
        let value_and_rest = &trimmed[eq + 2..];
        let close = value_and_rest
            .find('"')
            .ok_or("unterminated attribute value")?;
        check_escaped(&value_and_rest[..close])?;
        s = &value_and_rest[close + 1..];
    }
}

fn check_escaped(text: &str) -> Result<(), String> {
    if text.contains(['<', '>']) {
        return Err(format!("raw markup character in {text:?}"));
    }
    for (i, _) in text.match_indices('&') {
        let entity = &text[i + 1..];
        let end = entity.find(';').ok_or(format!("bare & in {text:?}"))?;
        let name = &entity[..end];
        let numeric = name.strip_prefix("#x").map_or_else(
            || {
                name.strip_prefix('#')
                    .is_some_and(|d| !d.is_empty() && d.chars().all(|c| c.is_ascii_digit()))
            },
            |h| !h.is_empty() && h.chars().all(|c| c.is_ascii_hexdigit()),
        );
        if !numeric && !["amp", "lt", "gt", "quot", "apos"].contains(&name) {
            return Err(format!("unknown entity &{name}; in {text:?}"));
        }
    }
    Ok(())
}

#[test]
fn checker_accepts_good_and_rejects_bad_documents() {
    let good = "<?xml version=\"1.0\"?>\n<!-- a - b --><svg a=\"1 &amp; 2\"><g><text>x &lt; y</text></g><line/></svg>\n";
    assert_eq!(check_well_formed(good), Ok(4));
    for bad in [
        "<svg><g></svg>",
        "<svg></g>",
        "<svg/><svg/>",
        "<svg a=1/>",
        "<svg a=\"1\" a=\"2\"/>",
        "<svg>a & b</svg>",
        "<svg>a > b</svg>",
        "<svg a=\"<\"/>",
        "<svg><!-- a -- b --></svg>",
        "<svg><g>",
        "text<svg/>",
    ] {
        assert!(check_well_formed(bad).is_err(), "{bad}");
    }
}
