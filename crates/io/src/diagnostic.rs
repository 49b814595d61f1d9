//! Diagnostics that point into scene files: `file:line:col`, the offending line and a caret,
//! the way compilers report. Errors stop the load (`SceneError`); warnings are collected and
//! handed back with the scene so the application decides how to show them.

use std::cell::{Cell, OnceCell};
use std::collections::HashSet;
use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::desc::Span;

/// How bad a diagnostic is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Severity {
    /// The scene cannot be loaded.
    Error,
    /// The scene loads, but something in it was ignored or replaced by a fallback.
    Warning,
}

/// One message about a place in a scene file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Diagnostic {
    pub severity: Severity,
    /// The scene file (as it was named to the loader).
    pub path: PathBuf,
    /// 1-based line.
    pub line: u32,
    /// 1-based column, counted in characters.
    pub column: u32,
    pub message: String,
    /// The offending line, for display: a span into the scene's text, shared by every
    /// diagnostic of the file, so that thousands of warnings on one long line cost no copies.
    pub source: Option<SourceLine>,
}

/// One line of a scene file's text: the whole text (shared) and the line's byte range in it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SourceLine {
    text: Arc<str>,
    range: Range<usize>,
    /// The column's byte offset in the line, where the loader knew it: an excerpt of a line
    /// of megabytes is then cut without counting its characters up to the column.
    caret: Option<usize>,
}

impl SourceLine {
    /// A line on its own (for diagnostics made outside the loader, and tests).
    pub fn new(line: &str) -> SourceLine {
        SourceLine {
            text: Arc::from(line),
            range: 0..line.len(),
            caret: None,
        }
    }

    /// The line's text, without its line break.
    pub fn as_str(&self) -> &str {
        &self.text[self.range.clone()]
    }
}

impl fmt::Display for Diagnostic {
    fn fmt(&self, formatter: &mut fmt::Formatter<'_>) -> fmt::Result {
        let label = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        write!(
            formatter,
            "{}:{}:{}: {label}: {}",
            self.path.display(),
            self.line,
            self.column,
            self.message
        )?;
        if let Some(excerpt) = self.source_excerpt() {
            write!(formatter, "\n{excerpt}")?;
        }
        Ok(())
    }
}

impl Diagnostic {
    /// `file:line:col: message`, then the offending line and a caret under the column: the
    /// diagnostic without its severity label, which every front end (the CLI, Python, the
    /// browser) puts in front as `error: ` or `warning: `, so all of them print the same text.
    pub fn located(&self) -> String {
        let mut text = format!(
            "{}:{}:{}: {}",
            self.path.display(),
            self.line,
            self.column,
            self.message
        );
        if let Some(excerpt) = self.source_excerpt() {
            text.push('\n');
            text.push_str(&excerpt);
        }
        text
    }

    /// The text of the offending line (without its line break), when known. `Display` shows
    /// an excerpt around the column when the line is very long.
    pub fn source_line(&self) -> Option<&str> {
        self.source.as_ref().map(SourceLine::as_str)
    }

    /// The offending line and, below it, a caret under the column: two lines for display, or
    /// `None` when the source line is unknown. A long line is cut to an excerpt around the
    /// column.
    pub fn source_excerpt(&self) -> Option<String> {
        let source = self.source.as_ref()?;
        let source_line = source.as_str();
        let column_index = self.column.saturating_sub(1) as usize;
        let caret = source
            .caret
            .filter(|&caret| source_line.is_char_boundary(caret))
            .unwrap_or_else(|| {
                source_line
                    .char_indices()
                    .nth(column_index)
                    .map_or(source_line.len(), |(at, _)| at)
            });
        let (shown, caret_offset) = excerpt_around(source_line, caret);
        // Reuse the line's own tabs in front of the caret so it lines up however wide the
        // terminal draws a tab.
        let caret_indent: String = shown
            .chars()
            .take(caret_offset)
            .map(|character| if character == '\t' { '\t' } else { ' ' })
            .collect();
        Some(format!("{shown}\n{caret_indent}^"))
    }
}

/// Lines longer than this are shown as an excerpt around the column (one course file is a
/// single line of 89,000 characters).
const SHOWN_LINE_LIMIT: usize = 120;

/// The part of `line` to display and the caret's character offset in it, for the caret at
/// byte `caret`. Only the characters shown are walked, so a warning on a line of megabytes
/// costs no more than one on a short line (thousands of them on one line were quadratic).
fn excerpt_around(line: &str, caret: usize) -> (String, usize) {
    let caret = caret.min(line.len());
    // At most four bytes a character: a line this short has few enough to count.
    if line.len() <= 4 * SHOWN_LINE_LIMIT && line.chars().count() <= SHOWN_LINE_LIMIT {
        return (line.to_owned(), line[..caret].chars().count());
    }
    // Half the excerpt before the caret, then the rest after it; where the line ends first,
    // the excerpt starts earlier, so that it always shows SHOWN_LINE_LIMIT characters.
    let mut before = line[..caret]
        .char_indices()
        .rev()
        .take(SHOWN_LINE_LIMIT / 2);
    let mut start = caret;
    let mut taken_before = 0;
    for (at, _) in before.by_ref() {
        start = at;
        taken_before += 1;
    }
    let after: Vec<usize> = line[start..]
        .char_indices()
        .map(|(at, _)| start + at)
        .take(SHOWN_LINE_LIMIT + 1)
        .collect();
    let mut end = after.get(SHOWN_LINE_LIMIT).copied().unwrap_or(line.len());
    let shortfall = SHOWN_LINE_LIMIT.saturating_sub(after.len().min(SHOWN_LINE_LIMIT));
    if shortfall > 0 {
        for (at, _) in line[..start].char_indices().rev().take(shortfall) {
            start = at;
            taken_before += 1;
        }
        end = line.len();
    }
    let mut shown = String::new();
    let mut caret_offset = taken_before;
    if start > 0 {
        shown.push_str("...");
        caret_offset += 3;
    }
    shown.push_str(&line[start..end]);
    if end < line.len() {
        shown.push_str("...");
    }
    (shown, caret_offset)
}

/// Why a scene could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file itself could not be read.
    #[error("cannot read scene file {}: {source}", path.display())]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    /// A syntax error or an invalid value, with its location.
    #[error("{0}")]
    Invalid(Diagnostic),
    /// Several located errors of one load, in the order they were met (at least two): the
    /// files a scene names that cannot be read are all reported, not only the first.
    #[error("{}", display_all(.0))]
    Several(Vec<Diagnostic>),
}

/// The diagnostics one after the other, a line break between them.
fn display_all(diagnostics: &[Diagnostic]) -> String {
    let shown: Vec<String> = diagnostics.iter().map(ToString::to_string).collect();
    shown.join("\n")
}

impl SceneError {
    /// The located diagnostic, when the error has one (the first, when it has several).
    pub fn diagnostic(&self) -> Option<&Diagnostic> {
        self.diagnostics().first()
    }

    /// Every located diagnostic of the error, in order: none for a scene file that could not
    /// be read, one for a syntax error, one for each file that could not be read.
    pub fn diagnostics(&self) -> &[Diagnostic] {
        match self {
            SceneError::Io { .. } => &[],
            SceneError::Invalid(diagnostic) => std::slice::from_ref(diagnostic),
            SceneError::Several(diagnostics) => diagnostics,
        }
    }

    /// The error of a load that met `errors` (at least one) before `stop`, the error that
    /// ended it, if any: one diagnostic alone is `Invalid`, more are `Several`.
    pub(crate) fn gathered(mut errors: Vec<Diagnostic>, stop: Option<SceneError>) -> SceneError {
        match stop {
            None => {}
            Some(SceneError::Invalid(diagnostic)) => errors.push(diagnostic),
            Some(SceneError::Several(more)) => errors.extend(more),
            // The scene file itself is unreadable: nothing else about it matters.
            Some(io @ SceneError::Io { .. }) => return io,
        }
        if errors.len() == 1 {
            SceneError::Invalid(errors.remove(0))
        } else {
            SceneError::Several(errors)
        }
    }
}

/// Byte offsets to 1-based line and character column. roxmltree's `text_pos_at` rescans the
/// document from the start on every call, which is quadratic over scenes with thousands of
/// shapes; this index answers each query with a binary search, or at once when the line is the
/// previous query's or the next one (the parsers ask in file order). Columns count characters:
/// in a text that is not all ASCII they come from the characters before every
/// `CHARS_EVERY`-th byte, counted once, so that a column on a line of megabytes costs at most
/// `CHARS_EVERY` bytes of counting, not the line's length.
pub(crate) struct LineIndex<'text> {
    text: &'text str,
    line_starts: Vec<usize>,
    /// The line index of the previous query.
    last_line: Cell<usize>,
    /// Characters before byte `k * CHARS_EVERY`, for every k; empty when every character is
    /// one byte (columns are then byte counts).
    chars_before: Vec<usize>,
}

/// Bytes between two entries of `LineIndex::chars_before`: its memory is an eighth of the
/// text's on 64-bit machines, and a column is counted over at most this many bytes.
const CHARS_EVERY: usize = 64;

impl<'text> LineIndex<'text> {
    pub fn new(text: &'text str) -> LineIndex<'text> {
        let mut line_starts = vec![0];
        line_starts.extend(memchr::memchr_iter(b'\n', text.as_bytes()).map(|offset| offset + 1));
        let chars_before = if text.is_ascii() {
            Vec::new()
        } else {
            let mut before = 0;
            let mut table = Vec::with_capacity(text.len() / CHARS_EVERY + 1);
            for block in text.as_bytes().chunks(CHARS_EVERY) {
                table.push(before);
                before += chars_in(block);
            }
            table.push(before);
            table
        };
        LineIndex {
            text,
            line_starts,
            last_line: Cell::new(0),
            chars_before,
        }
    }

    /// The characters that start before byte `offset`.
    fn chars_before(&self, offset: usize) -> usize {
        let block = offset / CHARS_EVERY;
        let start = block * CHARS_EVERY;
        self.chars_before[block] + chars_in(&self.text.as_bytes()[start..offset])
    }

    /// The index of the line holding `offset` (a char boundary no further than the text's end).
    fn line_of(&self, offset: usize) -> usize {
        let starts = &self.line_starts;
        let holds = |line: usize| {
            starts[line] <= offset && starts.get(line + 1).is_none_or(|&next| offset < next)
        };
        let last = self.last_line.get();
        let line = if holds(last) {
            last
        } else if last + 1 < starts.len() && holds(last + 1) {
            last + 1
        } else {
            starts.partition_point(|&start| start <= offset) - 1
        };
        self.last_line.set(line);
        line
    }

    pub fn span_at(&self, offset: usize) -> Span {
        let mut offset = offset.min(self.text.len());
        while !self.text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line_index = self.line_of(offset);
        let line_start = self.line_starts[line_index];
        let column = if self.chars_before.is_empty() {
            offset - line_start + 1
        } else {
            self.chars_before(offset) - self.chars_before(line_start) + 1
        };
        Span {
            line: u32::try_from(line_index + 1).unwrap_or(u32::MAX),
            column: u32::try_from(column).unwrap_or(u32::MAX),
        }
    }

    /// The byte offset, in the line at `range`, of 1-based character `column`: found from the
    /// counted blocks in O(log n + CHARS_EVERY), not by walking the line.
    fn offset_in_line(&self, range: &Range<usize>, column: u32) -> Option<usize> {
        let wanted = (column as usize).checked_sub(1)?;
        if self.chars_before.is_empty() {
            return Some(wanted.min(range.end - range.start));
        }
        let target = self.chars_before(range.start) + wanted;
        // The last block start at or before the target character, then a walk within it.
        let block = self
            .chars_before
            .partition_point(|&before| before <= target);
        // Within the line: a column past its end lands at the end.
        let mut block_start = (block.saturating_sub(1) * CHARS_EVERY)
            .max(range.start)
            .min(range.end);
        while !self.text.is_char_boundary(block_start) {
            block_start -= 1;
        }
        let skip = target - self.chars_before(block_start);
        Some(
            self.text[block_start..range.end]
                .char_indices()
                .nth(skip)
                .map_or(range.end, |(at, _)| block_start + at)
                - range.start,
        )
    }

    /// The text of 1-based `line`, without its line break.
    #[cfg(test)]
    pub fn line_text(&self, line: u32) -> Option<&'text str> {
        self.line_range(line).map(|range| &self.text[range])
    }

    /// The byte range of 1-based `line`, without its line break.
    pub fn line_range(&self, line: u32) -> Option<Range<usize>> {
        let index = (line as usize).checked_sub(1)?;
        let start = *self.line_starts.get(index)?;
        let mut end = self
            .line_starts
            .get(index + 1)
            .map_or(self.text.len(), |&next| next - 1);
        if end > start && self.text.as_bytes()[end - 1] == b'\r' {
            end -= 1;
        }
        Some(start..end)
    }
}

/// The characters that start in `bytes` (of UTF-8 text): every byte but continuation bytes.
fn chars_in(bytes: &[u8]) -> usize {
    bytes.iter().filter(|&&byte| (byte as i8) >= -0x40).count()
}

/// The collector every stage reports into: it knows the file and its text, so a `Span` is all a
/// caller needs to give.
pub(crate) struct Diagnostics<'text> {
    path: PathBuf,
    lines: LineIndex<'text>,
    /// The text, copied once when the first diagnostic needs it, shared by all of them.
    shared_text: OnceCell<Arc<str>>,
    warnings: Vec<Diagnostic>,
    /// Errors that did not stop the load at once (files that cannot be read), so that one
    /// load reports all of them; `finish` fails with them.
    errors: Vec<Diagnostic>,
    /// (line, column, message) of every warning kept: a repeated warning is dropped in O(1).
    seen: HashSet<(u32, u32, String)>,
    /// Warnings past `MAX_KEPT_WARNINGS`, counted only.
    dropped: usize,
    /// Where the last dropped warning was.
    last_dropped: Span,
}

/// The warnings a file keeps in full; the rest are counted, and one last warning says how many.
/// Ten thousand is far beyond what anyone reads, and a hostile file of ten million ignored
/// elements would otherwise hold gigabytes of messages.
pub const MAX_KEPT_WARNINGS: usize = 10_000;

/// The warning that stands for `dropped` warnings not kept.
pub(crate) fn dropped_message(dropped: usize) -> String {
    format!(
        "{dropped} more warning{} in this file not listed (only the first {MAX_KEPT_WARNINGS} are kept)",
        if dropped == 1 { "" } else { "s" }
    )
}

impl<'text> Diagnostics<'text> {
    pub fn new(path: &Path, text: &'text str) -> Diagnostics<'text> {
        Diagnostics {
            path: path.to_path_buf(),
            lines: LineIndex::new(text),
            shared_text: OnceCell::new(),
            warnings: Vec::new(),
            errors: Vec::new(),
            seen: HashSet::new(),
            dropped: 0,
            last_dropped: Span::default(),
        }
    }

    /// As `new`, for a text already shared: its diagnostics point into `text` itself rather
    /// than into a copy.
    pub fn new_shared(path: &Path, text: &'text Arc<str>) -> Diagnostics<'text> {
        let diagnostics = Diagnostics::new(path, text);
        let _ = diagnostics.shared_text.set(text.clone());
        diagnostics
    }

    /// A warning at `span`, for a caller that keeps its own list.
    pub fn warning(&self, span: Span, message: String) -> Diagnostic {
        self.diagnostic(Severity::Warning, span, message)
    }

    pub fn span_at(&self, offset: usize) -> Span {
        self.lines.span_at(offset)
    }

    fn diagnostic(&self, severity: Severity, span: Span, message: String) -> Diagnostic {
        let source = self.lines.line_range(span.line).map(|range| SourceLine {
            text: self
                .shared_text
                .get_or_init(|| Arc::from(self.lines.text))
                .clone(),
            caret: self.lines.offset_in_line(&range, span.column),
            range,
        });
        Diagnostic {
            severity,
            path: self.path.clone(),
            line: span.line,
            column: span.column,
            message,
            source,
        }
    }

    pub fn warn(&mut self, span: Span, message: impl Into<String>) {
        if self.warnings.len() >= MAX_KEPT_WARNINGS {
            self.dropped += 1;
            self.last_dropped = span;
            return;
        }
        let message = message.into();
        if !self.seen.insert((span.line, span.column, message.clone())) {
            return;
        }
        let diagnostic = self.diagnostic(Severity::Warning, span, message);
        self.warnings.push(diagnostic);
    }

    pub fn error(&self, span: Span, message: impl Into<String>) -> SceneError {
        SceneError::Invalid(self.diagnostic(Severity::Error, span, message.into()))
    }

    /// An error that does not stop the load at once: the load goes on, to find the others,
    /// and `finish` fails with all of them.
    pub fn error_later(&mut self, span: Span, message: impl Into<String>) {
        let diagnostic = self.diagnostic(Severity::Error, span, message.into());
        self.errors.push(diagnostic);
    }

    /// A file the scene names that cannot be read (`message` says which and why): an error
    /// unless `allowed` (`Limits::allow_missing_assets`), then a warning that ends with what
    /// is used instead (`fallback`).
    pub fn missing_asset(&mut self, span: Span, message: String, fallback: &str, allowed: bool) {
        if allowed {
            self.warn(span, format!("{message}; {fallback}"));
        } else {
            self.error_later(span, message);
        }
    }

    /// `error`, the one that stopped the load, after the errors met before it.
    pub fn stopped(&mut self, error: SceneError) -> SceneError {
        if self.errors.is_empty() {
            return error;
        }
        SceneError::gathered(std::mem::take(&mut self.errors), Some(error))
    }

    /// The warnings, or the errors met along the way when there were any.
    pub fn finish(self) -> Result<Vec<Diagnostic>, SceneError> {
        if !self.errors.is_empty() {
            return Err(SceneError::gathered(self.errors, None));
        }
        Ok(self.into_warnings())
    }

    pub fn into_warnings(mut self) -> Vec<Diagnostic> {
        if self.dropped > 0 {
            let last = self.diagnostic(
                Severity::Warning,
                self.last_dropped,
                dropped_message(self.dropped),
            );
            self.warnings.push(last);
        }
        self.warnings
    }
}

/// Names longer than this get no suggestion: no one mistypes a name of a hundred characters
/// into another, and the edit distance of two long names costs the product of their lengths.
const SUGGESTED_NAME_LIMIT: usize = 100;

/// " (did you mean `x`?)" when one of `candidates` is a plausible intended spelling of `word`:
/// equal ignoring case, or within an edit distance of about a third of its length. Every "did
/// you mean" goes through here. The work is bounded whatever the names: a word or candidate
/// over `SUGGESTED_NAME_LIMIT` characters is passed over, one whose length alone puts it out
/// of reach costs nothing more, and the rest cost at most 100 x 67 cells of one row each.
pub(crate) fn did_you_mean<'a>(
    word: &str,
    candidates: impl IntoIterator<Item = &'a str>,
) -> String {
    // Byte lengths bound character counts from above: a cheap first test.
    if word.len() > 4 * SUGGESTED_NAME_LIMIT {
        return String::new();
    }
    let word_lower: Vec<char> = word.chars().flat_map(char::to_lowercase).collect();
    if word_lower.len() > SUGGESTED_NAME_LIMIT {
        return String::new();
    }
    let allowed = (word.chars().count() / 3).max(1);
    let mut candidate_lower: Vec<char> = Vec::new();
    let mut best: Option<(usize, &str)> = None;
    for candidate in candidates {
        if candidate == word || candidate.len() > 4 * (SUGGESTED_NAME_LIMIT + allowed) {
            continue;
        }
        candidate_lower.clear();
        candidate_lower.extend(candidate.chars().flat_map(char::to_lowercase));
        // A closer candidate found already lowers the bound the rest must meet.
        let bound = best.map_or(allowed, |(distance, _)| distance);
        let Some(distance) = edit_distance_within(&word_lower, &candidate_lower, bound) else {
            continue;
        };
        // Ties go to the alphabetically first candidate, so messages do not depend on the
        // order of a hash map.
        if best.is_none_or(|current| (distance, candidate) < current) {
            best = Some((distance, candidate));
        }
    }
    match best {
        Some((_, candidate)) => format!(" (did you mean `{candidate}`?)"),
        None => String::new(),
    }
}

/// Edit distance over characters where swapping two neighbours counts as one edit (optimal
/// string alignment), since `bleu` for `blue` is a typical slip; `None` when it is over
/// `bound`. Three rows of the shorter string's length are held, not the whole table, and a
/// pair whose lengths differ by more than `bound` is answered at once, as is one whose row
/// minimum passes `bound` (the distance never falls below a row's minimum).
fn edit_distance_within(a: &[char], b: &[char], bound: usize) -> Option<usize> {
    let (a, b) = if a.len() < b.len() { (b, a) } else { (a, b) };
    if a.len() - b.len() > bound {
        return None;
    }
    let width = b.len() + 1;
    let mut before: Vec<usize> = vec![0; width];
    let mut previous: Vec<usize> = (0..width).collect();
    let mut current: Vec<usize> = vec![0; width];
    for i in 1..=a.len() {
        current[0] = i;
        let mut row_minimum = i;
        for j in 1..width {
            let substitution = previous[j - 1] + usize::from(a[i - 1] != b[j - 1]);
            let mut best = substitution.min(previous[j] + 1).min(current[j - 1] + 1);
            if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                best = best.min(before[j - 2] + 1);
            }
            current[j] = best;
            row_minimum = row_minimum.min(best);
        }
        // A transposition reaches back two rows, so a row's minimum bounds the distance from
        // below only together with the row before it.
        if row_minimum > bound && previous.iter().min().is_some_and(|&m| m > bound) {
            return None;
        }
        std::mem::swap(&mut before, &mut previous);
        std::mem::swap(&mut previous, &mut current);
    }
    let distance = previous[b.len()];
    (distance <= bound).then_some(distance)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn line_index_counts_characters_from_one() {
        let index = LineIndex::new("ab\ncé d\r\nxyz");
        assert_eq!(index.span_at(0), Span { line: 1, column: 1 });
        assert_eq!(index.span_at(3), Span { line: 2, column: 1 });
        // 'é' is two bytes but one column.
        assert_eq!(index.span_at(6), Span { line: 2, column: 3 });
        assert_eq!(index.line_text(2), Some("cé d"));
        assert_eq!(index.line_text(3), Some("xyz"));
        assert_eq!(index.line_text(4), None);
        assert_eq!(index.span_at(100), Span { line: 3, column: 4 });
    }

    /// The previous query's line is a hint, never the answer: every offset, asked in file
    /// order, backwards and in a scattered order, gets the line a search from scratch gives.
    #[test]
    fn line_lookups_agree_in_any_order() {
        for text in [
            "\n\nab\ncé d\r\n\n\nxyz\nlast line without a break",
            "\n\nab\nce d\r\n\n\nxyz\nlast line without a break",
        ] {
            lookups_agree(text);
        }
        // Lines longer than the blocks of counted characters, with characters of two, three
        // and four bytes on both sides of block edges.
        let mut random = crate::testing::xorshift(0x1234_5678_9abc_def1);
        let pieces = ["a", "é", "€", "𝄞", " ", "\n", "xyz"];
        let long: String = (0..900)
            .map(|_| {
                let pick = (random() % 40) as usize;
                pieces[if pick < pieces.len() { pick } else { 0 }]
            })
            .collect();
        lookups_agree(&long);
    }

    fn lookups_agree(text: &str) {
        let index = LineIndex::new(text);
        assert_eq!(index.chars_before.is_empty(), text.is_ascii());
        let expected = |offset: usize| {
            let line = text[..offset].matches('\n').count();
            let start = text[..offset].rfind('\n').map_or(0, |at| at + 1);
            Span {
                line: line as u32 + 1,
                column: text[start..offset].chars().count() as u32 + 1,
            }
        };
        let offsets: Vec<usize> = (0..=text.len())
            .filter(|&offset| text.is_char_boundary(offset))
            .collect();
        let forward = offsets.iter().copied();
        let backward = offsets.iter().rev().copied();
        let scattered = (0..offsets.len()).map(|i| offsets[(i * 7 + 3) % offsets.len()]);
        for offset in forward.chain(backward).chain(scattered) {
            assert_eq!(index.span_at(offset), expected(offset), "offset {offset}");
        }
    }

    #[test]
    fn repeated_warnings_are_kept_once() {
        let text = "one\ntwo\n";
        let mut diagnostics = Diagnostics::new(Path::new("s.xml"), text);
        let at = Span { line: 2, column: 1 };
        for _ in 0..3 {
            diagnostics.warn(at, "same");
        }
        diagnostics.warn(at, "other");
        diagnostics.warn(Span { line: 1, column: 1 }, "same");
        let warnings = diagnostics.into_warnings();
        assert_eq!(warnings.len(), 3);
        assert_eq!(warnings[0].source_line(), Some("two"));
        assert_eq!(warnings[2].source_line(), Some("one"));
    }

    #[test]
    fn suggestions_need_a_close_candidate() {
        assert_eq!(
            did_you_mean("Mirrored", ["Lambertian", "Mirror"]),
            " (did you mean `Mirror`?)"
        );
        assert_eq!(
            did_you_mean("cameras", ["camera", "shape"]),
            " (did you mean `camera`?)"
        );
        assert_eq!(did_you_mean("monster", ["center", "radius"]), "");
        assert_eq!(did_you_mean("bleu", ["blue"]), " (did you mean `blue`?)");
        assert_eq!(
            did_you_mean("envmapprefix", ["envMapPrefix"]),
            " (did you mean `envMapPrefix`?)"
        );
    }

    /// The whole table, as first written: the definition the bounded rows must keep.
    fn full_table_distance(a: &[char], b: &[char]) -> usize {
        let mut table = vec![vec![0usize; b.len() + 1]; a.len() + 1];
        for (i, row) in table.iter_mut().enumerate() {
            row[0] = i;
        }
        for (j, cell) in table[0].iter_mut().enumerate() {
            *cell = j;
        }
        for i in 1..=a.len() {
            for j in 1..=b.len() {
                let substitution = table[i - 1][j - 1] + usize::from(a[i - 1] != b[j - 1]);
                let mut best = substitution
                    .min(table[i - 1][j] + 1)
                    .min(table[i][j - 1] + 1);
                if i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] {
                    best = best.min(table[i - 2][j - 2] + 1);
                }
                table[i][j] = best;
            }
        }
        table[a.len()][b.len()]
    }

    /// Random words over a small alphabet (so that swaps and near misses are common): the
    /// bounded distance is the table's wherever that is within the bound, and `None` past it.
    #[test]
    fn bounded_distance_agrees_with_the_full_table() {
        let mut random = crate::testing::xorshift(0x5151_7a7a_0101_3c3c);
        let word = |random: &mut dyn FnMut() -> u64| -> Vec<char> {
            let length = (random() % 12) as usize;
            (0..length)
                .map(|_| ['a', 'b', 'c', 'é'][(random() % 4) as usize])
                .collect()
        };
        let mut within = 0;
        for _ in 0..3000 {
            let a = word(&mut random);
            let b = word(&mut random);
            let bound = (random() % 6) as usize;
            let exact = full_table_distance(&a, &b);
            let expected = (exact <= bound).then_some(exact);
            assert_eq!(
                edit_distance_within(&a, &b, bound),
                expected,
                "{a:?} {b:?} {bound}"
            );
            within += usize::from(expected.is_some());
        }
        assert!(within > 300, "only {within} pairs within their bound");
    }

    /// Issue 55: two names of 20,000 characters took a 3 GB table. Long names get no
    /// suggestion, and a long list of near-miss candidates is still answered.
    #[test]
    fn long_names_cost_no_table() {
        let (a, b) = ("a".repeat(20_000), "b".repeat(20_000));
        assert_eq!(did_you_mean(&b, [a.as_str()]), "");
        let near = format!("{}x", "a".repeat(99));
        assert_eq!(
            did_you_mean(&"a".repeat(100), [a.as_str(), near.as_str()]),
            format!(" (did you mean `{near}`?)")
        );
        // Not the first close candidate but the closest, ties alphabetically.
        assert_eq!(
            did_you_mean("shapes", ["shaper", "shape", "shapesx"]),
            " (did you mean `shape`?)"
        );
    }

    #[test]
    fn display_puts_a_caret_under_the_column() {
        let diagnostic = Diagnostic {
            severity: Severity::Warning,
            path: PathBuf::from("scene.xml"),
            line: 3,
            column: 5,
            message: "something".into(),
            source: Some(SourceLine::new("\tab cd")),
        };
        assert_eq!(
            diagnostic.to_string(),
            "scene.xml:3:5: warning: something\n\tab cd\n\t   ^"
        );
    }

    /// The excerpt cut at the byte offset the loader knows is the one cut by walking to the
    /// column, on long lines of mixed-width characters, at every column.
    #[test]
    fn excerpts_from_the_loader_agree_with_walking() {
        let mut random = crate::testing::xorshift(0x0bad_5eed_1234_4321);
        let pieces = ["a", "é", "€", "𝄞", "\t", "xyz"];
        let line: String = (0..400)
            .map(|_| pieces[(random() % pieces.len() as u64) as usize])
            .collect();
        let text = format!("first\n{line}\nlast");
        let diagnostics = Diagnostics::new(Path::new("s.xml"), &text);
        for column in 1..=line.chars().count() as u32 + 1 {
            let span = Span { line: 2, column };
            let from_loader = diagnostics.diagnostic(Severity::Error, span, "m".into());
            assert!(from_loader.source.as_ref().unwrap().caret.is_some());
            let walked = Diagnostic {
                source: Some(SourceLine::new(&line)),
                ..from_loader.clone()
            };
            assert_eq!(
                from_loader.source_excerpt(),
                walked.source_excerpt(),
                "{column}"
            );
        }
    }

    #[test]
    fn long_lines_are_shown_around_the_column() {
        let line = format!("{}X{}", "a".repeat(500), "b".repeat(500));
        let diagnostic = Diagnostic {
            severity: Severity::Error,
            path: PathBuf::from("long.json"),
            line: 1,
            column: 501,
            message: "here".into(),
            source: Some(SourceLine::new(&line)),
        };
        let shown = diagnostic.to_string();
        let lines: Vec<&str> = shown.lines().collect();
        assert!(lines[1].len() < 130);
        let caret = lines[2].find('^').unwrap();
        assert_eq!(lines[1].as_bytes()[caret], b'X');
    }
}
