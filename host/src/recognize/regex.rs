//! Action patterns: regular expressions over motion tokens, compiled to the device's form.
//!
//! Syntax: token names (see `figurine_recognizer::token`: `uf`, `d`, `.Yp`, `f.Zn` …)
//! separated by spaces, postfix `*` (zero or more), `+` (one or more), `?` (optional), `|`
//! (or) and parentheses. Example: `(uf df)+ u*`. STILL (`_`) is not allowed in patterns: the
//! automata never see stillness (pauses separate actions instead).
//!
//! Compilation is Glushkov's construction: one automaton state per token occurrence, so a
//! pattern of n tokens has n + 1 states and fits the device's bit-parallel `u64` masks when
//! n ≤ `MAX_POSITIONS`.

use anyhow::{bail, Result};
use figurine_recognizer::pattern::{encode_record, MAX_EDITS, MAX_POSITIONS};
use figurine_recognizer::token::{parse_symbol, symbol_matches, write_symbol, Symbol, Token};

/// Parsed regular expression.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Regex {
    /// One pattern symbol (a token, or a token with a wildcard half).
    Sym(Symbol),
    /// Concatenation.
    Cat(Vec<Regex>),
    /// Alternation.
    Alt(Vec<Regex>),
    /// Zero or more.
    Star(Box<Regex>),
    /// One or more.
    Plus(Box<Regex>),
    /// Zero or one.
    Opt(Box<Regex>),
}

/// The compiled (Glushkov) automaton of a pattern.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Compiled {
    /// Symbol of positions 1..=n.
    pub symbols: Vec<Symbol>,
    /// Follow sets of states 0..=n (bit i = state i; state 0 initial).
    pub follow: Vec<u64>,
    /// Accepting positions.
    pub last: u64,
    /// The whole expression is a `(…)+`: a cyclic action.
    pub cyclic: bool,
}

struct Parser<'a> {
    src: &'a str,
    pos: usize,
}

impl Parser<'_> {
    fn peek(&mut self) -> Option<char> {
        let rest = &self.src[self.pos..];
        let trimmed = rest.trim_start();
        self.pos += rest.len() - trimmed.len();
        trimmed.chars().next()
    }

    fn alt(&mut self) -> Result<Regex> {
        let mut items = vec![self.cat()?];
        while self.peek() == Some('|') {
            self.pos += 1;
            items.push(self.cat()?);
        }
        Ok(if items.len() == 1 {
            items.pop().unwrap_or(Regex::Cat(vec![]))
        } else {
            Regex::Alt(items)
        })
    }

    fn cat(&mut self) -> Result<Regex> {
        let mut items = Vec::new();
        while let Some(c) = self.peek() {
            if c == '|' || c == ')' {
                break;
            }
            let mut atom = self.atom()?;
            while let Some(op) = self.peek() {
                atom = match op {
                    '*' => Regex::Star(Box::new(atom)),
                    '+' => Regex::Plus(Box::new(atom)),
                    '?' => Regex::Opt(Box::new(atom)),
                    _ => break,
                };
                self.pos += 1;
            }
            match atom {
                Regex::Cat(v) => items.extend(v),
                a => items.push(a),
            }
        }
        if items.is_empty() {
            bail!("empty expression at byte {} of `{}`", self.pos, self.src);
        }
        Ok(if items.len() == 1 {
            items.pop().unwrap_or(Regex::Cat(vec![]))
        } else {
            Regex::Cat(items)
        })
    }

    fn atom(&mut self) -> Result<Regex> {
        match self.peek() {
            Some('(') => {
                self.pos += 1;
                let inner = self.alt()?;
                if self.peek() != Some(')') {
                    bail!("missing `)` at byte {} of `{}`", self.pos, self.src);
                }
                self.pos += 1;
                Ok(inner)
            }
            Some(c) if is_name_char(c) => {
                let rest = &self.src[self.pos..];
                let len = rest.find(|c: char| !is_name_char(c)).unwrap_or(rest.len());
                let name = &rest[..len];
                self.pos += len;
                if name == "_" {
                    bail!("STILL (`_`) cannot appear in a pattern");
                }
                match parse_symbol(name) {
                    Some(t) => Ok(Regex::Sym(t)),
                    None => bail!(
                        "`{name}` is not a token name (e.g. `uf`, `d`, `.Yp`, `f.Zn`, `uf~`, `~.Yp`)"
                    ),
                }
            }
            Some(c) => bail!("unexpected `{c}` at byte {} of `{}`", self.pos, self.src),
            None => bail!("unexpected end of `{}`", self.src),
        }
    }
}

fn is_name_char(c: char) -> bool {
    c.is_ascii_alphabetic() || c == '.' || c == '_' || c == '~'
}

/// A symbol's name.
pub fn symbol_name(s: Symbol) -> String {
    let mut out = String::new();
    let _ = write_symbol(s, &mut out);
    out
}

impl Regex {
    /// Parses a pattern source.
    pub fn parse(src: &str) -> Result<Regex> {
        let mut p = Parser { src, pos: 0 };
        let r = p.alt()?;
        if p.peek().is_some() {
            bail!(
                "unexpected `{}` at byte {} of `{src}`",
                &src[p.pos..],
                p.pos
            );
        }
        Ok(r)
    }

    /// Canonical source text (parses back to the same expression).
    pub fn to_source(&self) -> String {
        match self {
            Regex::Sym(t) => symbol_name(*t),
            Regex::Cat(v) => v
                .iter()
                .map(|r| match r {
                    Regex::Alt(_) => format!("({})", r.to_source()),
                    _ => r.to_source(),
                })
                .collect::<Vec<_>>()
                .join(" "),
            Regex::Alt(v) => v.iter().map(Regex::to_source).collect::<Vec<_>>().join("|"),
            Regex::Star(r) => format!("{}*", r.wrapped()),
            Regex::Plus(r) => format!("{}+", r.wrapped()),
            Regex::Opt(r) => format!("{}?", r.wrapped()),
        }
    }

    fn wrapped(&self) -> String {
        match self {
            Regex::Sym(_) => self.to_source(),
            _ => format!("({})", self.to_source()),
        }
    }

    /// Number of token occurrences (automaton positions).
    pub fn positions(&self) -> usize {
        match self {
            Regex::Sym(_) => 1,
            Regex::Cat(v) | Regex::Alt(v) => v.iter().map(Regex::positions).sum(),
            Regex::Star(r) | Regex::Plus(r) | Regex::Opt(r) => r.positions(),
        }
    }

    /// Glushkov construction.
    pub fn compile(&self) -> Result<Compiled> {
        let n = self.positions();
        if n == 0 || n > MAX_POSITIONS {
            bail!("pattern has {n} token positions; the device holds 1 to {MAX_POSITIONS}");
        }
        let mut symbols = Vec::with_capacity(n);
        let mut follow = vec![0u64; n + 1];
        let g = glushkov(self, &mut symbols, &mut follow);
        follow[0] = g.first;
        Ok(Compiled {
            symbols,
            follow,
            last: g.last,
            cyclic: matches!(self, Regex::Plus(_))
                || matches!(self, Regex::Alt(v) if v.iter().all(|r| matches!(r, Regex::Plus(_)))),
        })
    }
}

struct G {
    nullable: bool,
    first: u64,
    last: u64,
}

fn glushkov(r: &Regex, symbols: &mut Vec<Token>, follow: &mut [u64]) -> G {
    let add = |follow: &mut [u64], from: u64, to: u64| {
        for (i, f) in follow.iter_mut().enumerate().skip(1) {
            if from & (1 << i) != 0 {
                *f |= to;
            }
        }
    };
    match r {
        Regex::Sym(t) => {
            symbols.push(*t);
            let bit = 1u64 << symbols.len();
            G {
                nullable: false,
                first: bit,
                last: bit,
            }
        }
        Regex::Cat(v) => {
            let mut acc = G {
                nullable: true,
                first: 0,
                last: 0,
            };
            for item in v {
                let g = glushkov(item, symbols, follow);
                add(follow, acc.last, g.first);
                acc = G {
                    first: if acc.nullable {
                        acc.first | g.first
                    } else {
                        acc.first
                    },
                    last: if g.nullable {
                        acc.last | g.last
                    } else {
                        g.last
                    },
                    nullable: acc.nullable && g.nullable,
                };
            }
            acc
        }
        Regex::Alt(v) => {
            let mut acc = G {
                nullable: false,
                first: 0,
                last: 0,
            };
            for item in v {
                let g = glushkov(item, symbols, follow);
                acc.nullable |= g.nullable;
                acc.first |= g.first;
                acc.last |= g.last;
            }
            acc
        }
        Regex::Star(inner) | Regex::Plus(inner) | Regex::Opt(inner) => {
            let g = glushkov(inner, symbols, follow);
            if !matches!(r, Regex::Opt(_)) {
                add(follow, g.last, g.first);
            }
            G {
                nullable: g.nullable || !matches!(r, Regex::Plus(_)),
                ..g
            }
        }
    }
}

/// The default edit bound for a pattern whose shortest match has `min_len` tokens: `MAX_EDITS`,
/// always fewer than `min_len`. The device also holds every match to
/// `figurine_recognizer::segment::EDIT_SHARE` of the tokens it covers, so a short match gets
/// few edits and a long performance more.
pub fn default_edits(min_len: usize) -> u8 {
    MAX_EDITS.min(min_len.saturating_sub(1)) as u8
}

impl Compiled {
    /// Length of the shortest accepted token string.
    pub fn min_len(&self) -> usize {
        let mut reach = self.follow[0];
        let mut len = 1;
        while reach & self.last == 0 {
            let mut next = reach;
            for (i, f) in self.follow.iter().enumerate() {
                if reach & (1 << i) != 0 {
                    next |= f;
                }
            }
            if next == reach {
                return usize::MAX;
            }
            reach = next;
            len += 1;
        }
        len
    }

    /// The device record (see `figurine_recognizer::pattern` for the layout).
    pub fn record(&self, max_edits: u8) -> Result<Vec<u8>> {
        let mut out = Vec::new();
        encode_record(
            &mut out,
            &self.symbols,
            &self.follow,
            self.last,
            max_edits,
            self.cyclic,
        )
        .map_err(|e| anyhow::anyhow!("cannot encode pattern: {e}"))?;
        Ok(out)
    }

    /// Whether the pattern accepts exactly this token string (no edits).
    pub fn accepts(&self, tokens: &[Token]) -> bool {
        let mut d = 1u64;
        for &t in tokens {
            let mut next = 0u64;
            for (i, f) in self.follow.iter().enumerate() {
                if d & (1 << i) != 0 {
                    next |= f;
                }
            }
            d = 0;
            for (i, &s) in self.symbols.iter().enumerate() {
                if symbol_matches(s, t) && next & (1 << (i + 1)) != 0 {
                    d |= 1 << (i + 1);
                }
            }
            if d == 0 {
                return false;
            }
        }
        d & self.last != 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use figurine_recognizer::token::parse_token;

    fn toks(s: &str) -> Vec<Token> {
        s.split_whitespace()
            .map(|t| parse_token(t).unwrap())
            .collect()
    }

    #[test]
    fn parses_and_prints_round_trip() {
        for src in [
            "uf df",
            "(uf df)+ u*",
            "f+ (l|r)* .Yp?",
            "(u|d)+ (f b)*",
            "uf~ ~.Yp+",
        ] {
            let r = Regex::parse(src).unwrap();
            assert_eq!(Regex::parse(&r.to_source()).unwrap(), r, "{src}");
        }
        for bad in ["", "uf (", "uf )", "zz", "_", "uf ||", "*"] {
            assert!(Regex::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn glushkov_accepts_what_the_regex_means() {
        let c = Regex::parse("(uf df)+ u*").unwrap().compile().unwrap();
        assert!(c.accepts(&toks("uf df")));
        assert!(c.accepts(&toks("uf df uf df u")));
        assert!(!c.accepts(&toks("uf")));
        assert!(!c.accepts(&toks("uf df df")));
        assert_eq!(c.min_len(), 2);
        let c = Regex::parse("f+ (l|r)* b").unwrap().compile().unwrap();
        assert!(c.accepts(&toks("f l r l b")));
        assert!(c.accepts(&toks("f b")));
        assert!(!c.accepts(&toks("f l")));
        let c = Regex::parse("uf~+ ~.Yn").unwrap().compile().unwrap();
        assert!(c.accepts(&toks("uf.Zp uf d.Yn")));
    }

    #[test]
    fn records_load_on_the_device_side() {
        let c = Regex::parse("(uf df)+ (l|r)* d")
            .unwrap()
            .compile()
            .unwrap();
        let mut blob = b"FGL\x01\x01\0\0\0".to_vec();
        blob.extend(c.record(1).unwrap());
        let lib = figurine_recognizer::Library::from_bytes(&blob).unwrap();
        assert_eq!(lib.pattern(0).unwrap().min_len(), 3);
        let too_long = vec!["f b"; 17].join(" ");
        assert!(Regex::parse(&too_long).unwrap().compile().is_err());
        assert_eq!(default_edits(1), 0);
        assert_eq!(default_edits(2), 1);
        assert_eq!(default_edits(3), 2);
        assert_eq!(default_edits(30), 3);
    }
}
