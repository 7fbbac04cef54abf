//! Study reports as one HTML page: the markdown a report command writes (headings, paragraphs,
//! lists, tables, images, `code` and **bold**), converted so that the page opens in a browser
//! with its plots beside it. Only that subset of markdown is read; anything else stays text.

/// `text` with `&`, `<`, `>` and `"` escaped.
fn escape(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Inline markup of one line: `code`, **bold**, ![alt](src) images; the rest escaped.
fn inline(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while !rest.is_empty() {
        if let Some(r) = rest.strip_prefix("![")
            && let Some((alt, after)) = r.split_once("](")
            && let Some((src, tail)) = after.split_once(')')
        {
            out.push_str(&format!("<img alt=\"{}\" src=\"{}\">", escape(alt), escape(src)));
            rest = tail;
        } else if let Some(r) = rest.strip_prefix('`')
            && let Some((code, tail)) = r.split_once('`')
        {
            out.push_str(&format!("<code>{}</code>", escape(code)));
            rest = tail;
        } else if let Some(r) = rest.strip_prefix("**")
            && let Some((bold, tail)) = r.split_once("**")
        {
            out.push_str(&format!("<strong>{}</strong>", inline(bold)));
            rest = tail;
        } else {
            let c = rest.chars().next().unwrap_or(' ');
            out.push_str(&escape(&c.to_string()));
            rest = &rest[c.len_utf8()..];
        }
    }
    out
}

/// The cells of a table row `| a | b |`.
fn cells(line: &str) -> Vec<&str> {
    let inner = line.trim().trim_start_matches('|').trim_end_matches('|');
    inner.split('|').map(str::trim).collect()
}

fn is_separator(line: &str) -> bool {
    line.trim().starts_with('|') && line.chars().all(|c| matches!(c, '|' | '-' | ':' | ' '))
}

/// A markdown table starting at `lines[0]`: its HTML and the number of lines it took.
fn table(lines: &[&str]) -> (String, usize) {
    let n = lines.iter().take_while(|l| l.trim_start().starts_with('|')).count();
    let mut html = String::from("<table>\n");
    for (k, l) in lines[..n].iter().enumerate() {
        if is_separator(l) {
            continue;
        }
        let tag = if k == 0 && n > 1 && is_separator(lines[1]) { "th" } else { "td" };
        let row: Vec<String> = cells(l).iter().map(|c| format!("<{tag}>{}</{tag}>", inline(c))).collect();
        html.push_str(&format!("<tr>{}</tr>\n", row.concat()));
    }
    html.push_str("</table>\n");
    (html, n)
}

/// The report `markdown` as a standalone HTML page titled `title`.
pub fn markdown_to_html(title: &str, markdown: &str) -> String {
    let lines: Vec<&str> = markdown.lines().collect();
    let mut body = String::new();
    let mut i = 0;
    while i < lines.len() {
        let l = lines[i];
        let t = l.trim_start();
        if t.starts_with('|') {
            let (html, n) = table(&lines[i..]);
            body.push_str(&html);
            i += n;
            continue;
        }
        if let Some(level) = (1..=4).rev().find(|&k| t.starts_with(&format!("{} ", "#".repeat(k)))) {
            body.push_str(&format!("<h{level}>{}</h{level}>\n", inline(t[level + 1..].trim())));
        } else if let Some(item) = t.strip_prefix("- ") {
            body.push_str("<ul>\n");
            body.push_str(&format!("<li>{}</li>\n", inline(item)));
            while let Some(next) = lines.get(i + 1).and_then(|n| n.trim_start().strip_prefix("- ")) {
                body.push_str(&format!("<li>{}</li>\n", inline(next)));
                i += 1;
            }
            body.push_str("</ul>\n");
        } else if !t.is_empty() {
            body.push_str(&format!("<p>{}</p>\n", inline(t)));
        }
        i += 1;
    }
    format!(
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{}</title>\n<style>\
body{{font-family:sans-serif;max-width:1100px;margin:2em auto;line-height:1.4}}\
table{{border-collapse:collapse;margin:1em 0}}td,th{{border:1px solid #bbb;padding:3px 8px;font-size:90%}}\
th{{background:#eee}}img{{max-width:100%}}code{{background:#f4f4f4}}</style></head>\n<body>\n{body}</body></html>\n",
        escape(title)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headings_tables_lists_images_and_code_become_html() {
        let md = "# Schemes compared\n\n| scheme | heating kW |\n|---|---|\n| a <b> | 1.5 |\n\n- one `x[1]`\n- **two**\n\n![heating](energy.png)\n";
        let html = markdown_to_html("t", md);
        assert!(html.contains("<h1>Schemes compared</h1>"), "{html}");
        assert!(html.contains("<tr><th>scheme</th><th>heating kW</th></tr>"), "{html}");
        assert!(html.contains("<tr><td>a &lt;b&gt;</td><td>1.5</td></tr>"), "{html}");
        assert!(html.contains("<li>one <code>x[1]</code></li>") && html.contains("<strong>two</strong>"), "{html}");
        assert!(html.contains("<img alt=\"heating\" src=\"energy.png\">"), "{html}");
        assert!(!html.contains("|---|"));
    }
}
