//! An independent recogniser of the RAPID module syntax, written for the
//! tests from the RAPID reference manual's grammar (Technical reference
//! manual – RAPID kernel: lexical elements, data declarations, routine
//! declarations, statements, procedure calls with required, named and
//! optional (`\switch`, `\arg := value`) arguments, aggregates), not from
//! our reader (`src/program/abb/read.rs`), with which it shares no
//! code. It accepts the subset a generated motion module needs:
//!
//! ```text
//! module      = "MODULE" ident [ "(" ident { "," ident } ")" ] { data_decl } { routine } "ENDMODULE"
//! data_decl   = [ "LOCAL" | "TASK" ] routine_data
//! routine_data = ( "PERS" | "VAR" | "CONST" ) ident ident [ ":=" expr ] ";"
//! routine     = [ "LOCAL" ] "PROC" ident "(" ")" { routine_data } { statement } "ENDPROC"
//! statement   = ident ":=" expr ";" | ident [ arguments ] ";"
//!             | "%" expr "%" [ arguments ] ";"      (late binding: the procedure's name as a string)
//! arguments   = argument { "," argument | optional }   (the first may be an optional)
//! argument    = optional | [ ident ":=" ] expr
//! optional    = "\" ident [ ":=" expr ]
//! expr        = term { ( "+" | "-" | "*" | "/" ) term }
//! term        = number | string | ident [ "(" [ arguments ] ")" ] | "[" expr { "," expr } "]"
//!             | ( "-" | "+" ) term | "(" expr ")"
//! ```
//!
//! Lexical rules checked: identifiers are a letter then letters, digits or
//! `_`, at most 32 characters, and not a reserved word; numbers are
//! `digits [. digits] [E [+|-] digits]` (or `. digits`); strings are in
//! double quotes on one line (at most 80 characters); `!` starts a comment
//! to the end of the line; every other character is an error.
//!
//! [`check_task`] adds a scope model of a task made of several modules, from
//! the RAPID reference ("Basic Characteristics RAPID", §3.1 routine scope,
//! §5.1 data scope; as published on yumpu, document 5679047 pp. 87 and 96):
//! a name declared `LOCAL` is visible in its module only and hides a global
//! one of the same name; a global name is visible in every module of the
//! task, so two globals of one name clash; routine and module names share
//! one name space (vendor notes §3, after RoboDK's ABB post, which names
//! its modules `MOD_<prog>` for that reason); names are compared without
//! case.

/// A token with its line.
#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(String),
    Num,
    Str,
    Punct(&'static str),
}

/// RAPID's reserved words (RAPID kernel manual, "Reserved words"), none of
/// which may be an identifier.
const RESERVED: &[&str] = &[
    "ALIAS",
    "AND",
    "BACKWARD",
    "CASE",
    "CONNECT",
    "CONST",
    "DEFAULT",
    "DIV",
    "DO",
    "ELSE",
    "ELSEIF",
    "ENDFOR",
    "ENDFUNC",
    "ENDIF",
    "ENDMODULE",
    "ENDPROC",
    "ENDRECORD",
    "ENDTEST",
    "ENDTRAP",
    "ENDWHILE",
    "ERROR",
    "EXIT",
    "FALSE",
    "FOR",
    "FROM",
    "FUNC",
    "GOTO",
    "IF",
    "INOUT",
    "LOCAL",
    "MOD",
    "MODULE",
    "NOSTEPIN",
    "NOT",
    "NOVIEW",
    "OR",
    "PERS",
    "PROC",
    "RAISE",
    "READONLY",
    "RECORD",
    "RETRY",
    "RETURN",
    "STEP",
    "SYSMODULE",
    "TEST",
    "THEN",
    "TO",
    "TRAP",
    "TRUE",
    "TRYNEXT",
    "UNDO",
    "VAR",
    "VIEWONLY",
    "WHILE",
    "WITH",
    "XOR",
];

/// Words that may stand as values although reserved.
const LITERAL_WORDS: &[&str] = &["TRUE", "FALSE"];

fn lex(text: &str) -> Result<Vec<(Tok, usize)>, String> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let n = n + 1;
        let c: Vec<char> = line.chars().collect();
        let mut i = 0;
        while i < c.len() {
            let ch = c[i];
            if ch == ' ' || ch == '\t' {
                i += 1;
            } else if ch == '!' {
                break;
            } else if ch.is_ascii_alphabetic() {
                let s = i;
                while i < c.len() && (c[i].is_ascii_alphanumeric() || c[i] == '_') {
                    i += 1;
                }
                let w: String = c[s..i].iter().collect();
                if w.len() > 32 {
                    return Err(format!("line {n}: identifier `{w}` longer than 32"));
                }
                out.push((Tok::Ident(w), n));
            } else if ch.is_ascii_digit()
                || (ch == '.' && c.get(i + 1).is_some_and(|d| d.is_ascii_digit()))
            {
                let digits = |i: &mut usize| {
                    let s = *i;
                    while *i < c.len() && c[*i].is_ascii_digit() {
                        *i += 1;
                    }
                    *i > s
                };
                digits(&mut i);
                if c.get(i) == Some(&'.') {
                    i += 1;
                    digits(&mut i);
                }
                if matches!(c.get(i), Some('E' | 'e')) {
                    i += 1;
                    if matches!(c.get(i), Some('+' | '-')) {
                        i += 1;
                    }
                    if !digits(&mut i) {
                        return Err(format!("line {n}: bad exponent"));
                    }
                }
                if c.get(i)
                    .is_some_and(|d| d.is_ascii_alphanumeric() || *d == '.')
                {
                    return Err(format!("line {n}: bad number at column {}", i + 1));
                }
                out.push((Tok::Num, n));
            } else if ch == '"' {
                let s = i;
                i += 1;
                loop {
                    match c.get(i) {
                        None => return Err(format!("line {n}: unterminated string")),
                        Some('"') if c.get(i + 1) == Some(&'"') => i += 2,
                        Some('"') => break,
                        Some(_) => i += 1,
                    }
                }
                i += 1;
                if i - s - 2 > 80 {
                    return Err(format!("line {n}: string longer than 80 characters"));
                }
                out.push((Tok::Str, n));
            } else {
                let two: String = c[i..(i + 2).min(c.len())].iter().collect();
                let p = match two.as_str() {
                    ":=" => Some(":="),
                    _ => None,
                };
                if let Some(p) = p {
                    out.push((Tok::Punct(p), n));
                    i += 2;
                    continue;
                }
                let p = match ch {
                    ';' => ";",
                    ',' => ",",
                    '[' => "[",
                    ']' => "]",
                    '(' => "(",
                    ')' => ")",
                    '\\' => "\\",
                    '+' => "+",
                    '-' => "-",
                    '*' => "*",
                    '/' => "/",
                    '%' => "%",
                    _ => return Err(format!("line {n}: unexpected character `{ch}`")),
                };
                out.push((Tok::Punct(p), n));
                i += 1;
            }
        }
    }
    Ok(out)
}

/// A name declared at module level: data or routine.
#[derive(Debug, Clone)]
struct Symbol {
    name: String,
    local: bool,
    line: usize,
}

struct Parser {
    toks: Vec<(Tok, usize)>,
    at: usize,
    /// The module's name.
    module: String,
    /// The names declared at module level, in order.
    symbols: Vec<Symbol>,
}

impl Parser {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.at).map(|t| &t.0)
    }

    fn line(&self) -> usize {
        self.toks
            .get(self.at)
            .or(self.toks.last())
            .map_or(0, |t| t.1)
    }

    fn err<T>(&self, what: &str) -> Result<T, String> {
        Err(format!(
            "line {}: expected {what}, found {:?}",
            self.line(),
            self.peek()
        ))
    }

    fn is_word(&self, w: &str) -> bool {
        matches!(self.peek(), Some(Tok::Ident(x)) if x == w)
    }

    fn is_punct(&self, p: &str) -> bool {
        matches!(self.peek(), Some(Tok::Punct(x)) if *x == p)
    }

    fn word(&mut self, w: &str) -> Result<(), String> {
        if self.is_word(w) {
            self.at += 1;
            Ok(())
        } else {
            self.err(w)
        }
    }

    fn punct(&mut self, p: &str) -> Result<(), String> {
        if self.is_punct(p) {
            self.at += 1;
            Ok(())
        } else {
            self.err(&format!("`{p}`"))
        }
    }

    /// An identifier that is not a reserved word.
    fn ident(&mut self) -> Result<String, String> {
        match self.peek() {
            Some(Tok::Ident(w)) if !RESERVED.contains(&w.as_str()) => {
                let w = w.clone();
                self.at += 1;
                Ok(w)
            }
            _ => self.err("an identifier"),
        }
    }

    fn module(&mut self) -> Result<(), String> {
        self.word("MODULE")?;
        self.module = self.ident()?;
        if self.is_punct("(") {
            self.at += 1;
            loop {
                // module attributes are reserved words (SYSMODULE, NOVIEW...)
                match self.peek() {
                    Some(Tok::Ident(_)) => self.at += 1,
                    _ => return self.err("a module attribute"),
                }
                if self.is_punct(",") {
                    self.at += 1;
                } else {
                    break;
                }
            }
            self.punct(")")?;
        }
        while self.starts_data_decl() {
            self.data_decl(true)?;
        }
        while !self.is_word("ENDMODULE") {
            self.routine()?;
        }
        self.word("ENDMODULE")?;
        if self.at != self.toks.len() {
            return self.err("the end of the file after ENDMODULE");
        }
        Ok(())
    }

    fn starts_data_decl(&self) -> bool {
        let w = |k: usize| match self.toks.get(self.at + k) {
            Some((Tok::Ident(x), _)) => x.as_str(),
            _ => "",
        };
        matches!(w(0), "PERS" | "VAR" | "CONST")
            || (matches!(w(0), "LOCAL" | "TASK") && matches!(w(1), "PERS" | "VAR" | "CONST"))
    }

    /// A data declaration; `LOCAL` and `TASK` at module level only.
    fn data_decl(&mut self, module_level: bool) -> Result<(), String> {
        let local = self.is_word("LOCAL");
        if local || self.is_word("TASK") {
            if !module_level {
                return self.err("routine data without LOCAL or TASK (module level only)");
            }
            self.at += 1;
        }
        if self.is_word("PERS") || self.is_word("VAR") || self.is_word("CONST") {
            self.at += 1;
        } else {
            return self.err("PERS, VAR or CONST");
        }
        self.ident()?; // type
        let line = self.line();
        let name = self.ident()?;
        if module_level {
            self.symbols.push(Symbol { name, local, line });
        }
        if self.is_punct(":=") {
            self.at += 1;
            self.expr()?;
        }
        self.punct(";")
    }

    fn routine(&mut self) -> Result<(), String> {
        let local = self.is_word("LOCAL");
        if local {
            self.at += 1;
        }
        self.word("PROC")?;
        let line = self.line();
        let name = self.ident()?;
        self.symbols.push(Symbol { name, local, line });
        self.punct("(")?;
        self.punct(")")?;
        while self.starts_data_decl() {
            self.data_decl(false)?;
        }
        while !self.is_word("ENDPROC") {
            if self.peek().is_none() {
                return self.err("ENDPROC");
            }
            self.statement()?;
        }
        self.word("ENDPROC")
    }

    fn statement(&mut self) -> Result<(), String> {
        // late binding (RAPID kernel, "Procedure call": the procedure name
        // given as a string expression between `%`)
        if self.is_punct("%") {
            self.at += 1;
            self.expr()?;
            self.punct("%")?;
            if !self.is_punct(";") {
                self.arguments()?;
            }
            return self.punct(";");
        }
        self.ident()?;
        if self.is_punct(":=") {
            self.at += 1;
            self.expr()?;
            return self.punct(";");
        }
        if !self.is_punct(";") {
            self.arguments()?;
        }
        self.punct(";")
    }

    fn arguments(&mut self) -> Result<(), String> {
        self.argument()?;
        loop {
            if self.is_punct(",") {
                self.at += 1;
                self.argument()?;
            } else if self.is_punct("\\") {
                self.optional()?;
            } else {
                return Ok(());
            }
        }
    }

    fn argument(&mut self) -> Result<(), String> {
        if self.is_punct("\\") {
            return self.optional();
        }
        // named argument `name := value`
        if matches!(self.peek(), Some(Tok::Ident(_)))
            && matches!(self.toks.get(self.at + 1), Some((Tok::Punct(":="), _)))
        {
            self.ident()?;
            self.at += 1;
        }
        self.expr()
    }

    fn optional(&mut self) -> Result<(), String> {
        self.punct("\\")?;
        self.ident()?;
        if self.is_punct(":=") {
            self.at += 1;
            self.expr()?;
        }
        Ok(())
    }

    fn expr(&mut self) -> Result<(), String> {
        self.term()?;
        while ["+", "-", "*", "/"].iter().any(|p| self.is_punct(p)) {
            self.at += 1;
            self.term()?;
        }
        Ok(())
    }

    fn term(&mut self) -> Result<(), String> {
        match self.peek() {
            Some(Tok::Num | Tok::Str) => {
                self.at += 1;
                Ok(())
            }
            Some(Tok::Ident(w)) if LITERAL_WORDS.contains(&w.as_str()) => {
                self.at += 1;
                Ok(())
            }
            Some(Tok::Ident(_)) => {
                self.ident()?;
                if self.is_punct("(") {
                    self.at += 1;
                    if !self.is_punct(")") {
                        self.arguments()?;
                    }
                    self.punct(")")?;
                }
                Ok(())
            }
            Some(Tok::Punct("[")) => {
                self.at += 1;
                self.expr()?;
                while self.is_punct(",") {
                    self.at += 1;
                    self.expr()?;
                }
                self.punct("]")
            }
            Some(Tok::Punct("-" | "+")) => {
                self.at += 1;
                self.term()
            }
            Some(Tok::Punct("(")) => {
                self.at += 1;
                self.expr()?;
                self.punct(")")
            }
            _ => self.err("a value"),
        }
    }
}

/// Checks that `text` is one RAPID module in the grammar of the module doc.
///
/// # Errors
/// The first syntax error with its line.
pub fn check_module(text: &str) -> Result<(), String> {
    parse(text).map(|_| ())
}

/// The module's name and module-level symbols.
fn parse(text: &str) -> Result<(String, Vec<Symbol>), String> {
    let toks = lex(text)?;
    let mut p = Parser {
        toks,
        at: 0,
        module: String::new(),
        symbols: Vec::new(),
    };
    p.module()?;
    Ok((p.module, p.symbols))
}

/// Checks that `modules` (each one module's text) load together into one
/// task: each in the grammar, and no name clash in the scope model of the
/// module doc. Names are compared without case.
///
/// # Errors
/// The first syntax error (with the module's index) or the first clash,
/// naming both sides.
pub fn check_task(modules: &[&str]) -> Result<(), String> {
    let mut parsed = Vec::new();
    for (k, text) in modules.iter().enumerate() {
        parsed.push(parse(text).map_err(|e| format!("module {k}: {e}"))?);
    }
    let key = |s: &str| s.to_ascii_lowercase();
    // the task's global name space: module names and global symbols
    let mut global: std::collections::HashMap<String, String> = std::collections::HashMap::new();
    let mut add = |name: &str, what: String| match global.get(&key(name)) {
        Some(other) => Err(format!("{what} clashes with {other}")),
        None => {
            global.insert(key(name), what);
            Ok(())
        }
    };
    for (module, _) in &parsed {
        add(module, format!("MODULE {module}"))?;
    }
    for (module, symbols) in &parsed {
        for s in symbols.iter().filter(|s| !s.local) {
            add(
                &s.name,
                format!("global {} ({module} line {})", s.name, s.line),
            )?;
        }
    }
    // inside a module: every name once, whatever its scope
    for (module, symbols) in &parsed {
        let mut seen: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
        seen.insert(key(module), 0);
        for s in symbols {
            if let Some(l) = seen.insert(key(&s.name), s.line) {
                return Err(format!(
                    "{} ({module} line {}) is declared twice in its module (line {l}; 0 = the module's own name)",
                    s.name, s.line
                ));
            }
        }
    }
    Ok(())
}

/// The recogniser itself: it accepts a hand-written module in the style of
/// the RAPID reference manual's examples and rejects each kind of error.
#[test]
fn the_recogniser_accepts_rapid_and_rejects_errors() {
    let good = "MODULE Demo (SYSMODULE, NOVIEW)
  ! a comment
  LOCAL PERS tooldata tGun := [TRUE,[[10,0,200],[1,0,0,0]],[2,[0,0,100],[1,0,0,0],0,0,0]];
  TASK PERS seamdata sm1 := [0.5,0.5,[1,0,0,0,0,0,0,0,0],0,0,0,0,0,[0,0,0,0,0,0,0,0,0],0,0,[0,0,0,0,0,0,0,0,0],0,0,[0,0,0,0,0,0,0,0,0],0];
  CONST robtarget p1 := [[1.5E+02,-.5,3],[1,0,0,0],[0,0,0,0],[9E+09,9E+09,9E+09,9E+09,9E+09,9E+09]];
  VAR num n;
  PROC main()
    VAR num k := 2;
    ConfL \\Off;
    n := n + 1 * (k - 2);
    MoveL p1, v100\\T:=2.5, z10, tGun\\WObj:=wobj0;
    ArcL p1, v100, sm1, weld1\\Weave:=weave1, fine, tGun;
    WaitDI diReady, 1;
    TPWrite \"n = \"\\Num:=n;
    StartLoad \\Dynamic, \"HOME:/PART.mod\", ld1;
    WaitLoad ld1;
    %\"PART\"%;
    UnLoad \"HOME:/PART.mod\";
    Stop;
  ENDPROC
ENDMODULE
";
    check_module(good).unwrap_or_else(|e| panic!("{e}"));
    for (bad, why) in [
        (good.replace("Stop;", "Stop"), "missing `;`"),
        (good.replace("  ENDPROC\n", ""), "missing ENDPROC"),
        (good.replace("ENDMODULE\n", ""), "missing ENDMODULE"),
        (good.replace("VAR num n;", "VAR num 1n;"), "bad identifier"),
        (
            good.replace("VAR num n;", "VAR num IF;"),
            "reserved word as a name",
        ),
        (
            good.replace("VAR num n;", &format!("VAR num n{};", "x".repeat(32))),
            "identifier of 33 characters",
        ),
        (
            good.replace("[1,0,0,0]]", "[1,0,0,0]"),
            "unbalanced aggregate",
        ),
        (good.replace("-.5", "1.2.3"), "bad number"),
        (
            good.replace("v100\\T", "v100 \\T:"),
            "bad optional argument",
        ),
        (
            good.replace("CONST robtarget p1", "CONST p1"),
            "declaration without a type",
        ),
        (good.replace("n := n", "n = n"), "`=` for `:=`"),
        (good.replace("Stop;", "Stop; # x"), "stray character"),
        (
            good.replace("%\"PART\"%;", "%\"PART\";"),
            "late binding without its closing `%`",
        ),
        (
            format!("{good}MODULE Two\nENDMODULE\n"),
            "text after ENDMODULE",
        ),
        (good.replace("\"n = \"", "\"n = "), "unterminated string"),
        (
            good.replace("VAR num k := 2;", "LOCAL VAR num k := 2;"),
            "LOCAL inside a routine",
        ),
    ] {
        assert!(check_module(&bad).is_err(), "accepted with {why}:\n{bad}");
    }
}

/// The scope model: `LOCAL` names of one spelling in two modules load
/// together, as do a routine and a module of different names; two globals
/// of one name (in any case), a routine named like a module, and a name
/// declared twice in one module clash.
#[test]
fn the_scope_model_accepts_local_names_and_rejects_clashes() {
    let a = "MODULE A
  LOCAL PERS num n := 1;
  LOCAL PROC helper()
    Stop;
  ENDPROC
  PROC runA()
    helper;
  ENDPROC
ENDMODULE
";
    let b = "MODULE B
  LOCAL PERS num n := 2;
  PERS num shared := 0;
  LOCAL PROC helper()
    Stop;
  ENDPROC
  PROC main()
    runA;
  ENDPROC
ENDMODULE
";
    check_task(&[a, b]).unwrap_or_else(|e| panic!("{e}"));
    for (task, why) in [
        (
            vec![
                a.to_string(),
                b.replace("LOCAL PERS num n", "PERS num n"),
                a.replace("MODULE A", "MODULE C")
                    .replace("LOCAL PERS num n", "PERS num N")
                    .replace("runA", "runC"),
            ],
            "two globals n and N",
        ),
        (
            vec![a.to_string(), b.replace("PROC main", "PROC runA")],
            "two global routines runA",
        ),
        (
            vec![a.replace("PROC runA", "PROC B"), b.to_string()],
            "a routine named like a module",
        ),
        (
            vec![
                a.replace("LOCAL PROC helper", "LOCAL PROC n"),
                b.to_string(),
            ],
            "a name twice in one module",
        ),
        (vec![a.to_string(), a.to_string()], "two modules A"),
    ] {
        let texts: Vec<&str> = task.iter().map(String::as_str).collect();
        assert!(check_task(&texts).is_err(), "accepted {why}");
    }
}
