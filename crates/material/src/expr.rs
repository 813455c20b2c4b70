//! Energies written as text: a small expression language, parsed once and evaluated on any
//! [`Real`] scalar (plain numbers, the second-order dual numbers of the FE, Taylor jets).
//!
//! ```text
//! expr   := term (('+' | '-') term)*
//! term   := unary (('*' | '/') unary)*
//! unary  := ('-' | '+') unary | power
//! power  := atom (('^' | '**') unary)?          right-associative: 2^3^2 = 2^9
//! atom   := number | name | name '(' expr (',' expr)* ')' | '(' expr ')'
//! ```
//!
//! Names are the energy's variables (`I1`, `I2`; or the stretch `l`) and the law's parameters,
//! which are folded to constants when the text is parsed. Functions: `ln` (also `log`, the
//! natural logarithm), `exp`, `sqrt`, `pow(a, b)`, `sinh`, `cosh`, `tanh`. A constant
//! integer exponent is evaluated as repeated products (exact for negative bases too), any
//! other power as exp(b ln a).
//!
//! Errors name the column (1-based, in characters) and what was expected there.

use crate::dual::Real;
use crate::MaterialError;
use std::collections::BTreeMap;

/// A parsed expression: nodes in an arena, the root last.
#[derive(Clone, Debug, PartialEq)]
pub struct Expr {
    nodes: Vec<Node>,
    /// the text it was parsed from
    text: String,
    /// the variables it may name, in the order [`Expr::eval`] takes their values
    variables: Vec<String>,
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Node {
    Const(f64),
    Var(usize),
    Neg(usize),
    Add(usize, usize),
    Sub(usize, usize),
    Mul(usize, usize),
    Div(usize, usize),
    /// a constant integer exponent
    PowI(usize, i32),
    /// a constant exponent
    PowF(usize, f64),
    Pow(usize, usize),
    Call(Func, usize),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Func {
    Ln,
    Exp,
    Sqrt,
    Sinh,
    Cosh,
    Tanh,
}

const FUNCTIONS: &str = "ln, log, exp, sqrt, pow, sinh, cosh, tanh";

#[derive(Clone, Debug, PartialEq)]
enum Token {
    Num(f64),
    Name(String),
    Op(char),
    /// `**`
    Pow,
    Comma,
    Open,
    Close,
    End,
}

/// The deepest nesting an energy may have (parentheses, signs, exponents and function calls
/// inside one another): 200. The parser descends once per level; a hand-written energy nests a
/// few levels, and 200 keeps the descent far inside the smallest stack a thread runs it on.
pub const MAX_DEPTH: usize = 200;

/// The most operations an energy may have after its constants are folded: 100,000 (a 1 MiB
/// case holds about 250,000 characters of `+ x`; each operation costs every evaluation at
/// every Gauss point).
pub const MAX_NODES: usize = 100_000;

/// The longest excerpt of an energy an error message quotes around its column.
const EXCERPT: usize = 40;

struct Parser<'a> {
    tokens: Vec<(Token, usize)>,
    pos: usize,
    /// the current nesting (see [`MAX_DEPTH`])
    depth: usize,
    nodes: Vec<Node>,
    variables: &'a [&'a str],
    parameters: &'a BTreeMap<String, f64>,
    text: &'a str,
}

/// An error at `column` of `text`, quoting at most [`EXCERPT`] characters on each side of it
/// (a 1 MiB energy is not echoed whole).
fn error(text: &str, column: usize, message: String) -> MaterialError {
    let chars: Vec<char> = text.chars().collect();
    let at = column.saturating_sub(1).min(chars.len());
    let (from, to) = (at.saturating_sub(EXCERPT), (at + EXCERPT).min(chars.len()));
    let excerpt = format!(
        "{}{}{}",
        if from > 0 { "…" } else { "" },
        chars[from..to].iter().collect::<String>(),
        if to < chars.len() { "…" } else { "" }
    );
    MaterialError::Expression {
        energy: excerpt.into(),
        column,
        message: message.into(),
    }
}

fn tokenize(text: &str) -> Result<Vec<(Token, usize)>, MaterialError> {
    let chars: Vec<char> = text.chars().collect();
    let mut out = vec![];
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let col = i + 1;
        if c.is_whitespace() {
            i += 1;
            continue;
        }
        if c.is_ascii_digit() || (c == '.' && chars.get(i + 1).is_some_and(|d| d.is_ascii_digit()))
        {
            let start = i;
            while i < chars.len() && (chars[i].is_ascii_digit() || chars[i] == '.') {
                i += 1;
            }
            if i < chars.len() && (chars[i] == 'e' || chars[i] == 'E') {
                let mut j = i + 1;
                if j < chars.len() && (chars[j] == '+' || chars[j] == '-') {
                    j += 1;
                }
                if j < chars.len() && chars[j].is_ascii_digit() {
                    i = j;
                    while i < chars.len() && chars[i].is_ascii_digit() {
                        i += 1;
                    }
                }
            }
            let s: String = chars[start..i].iter().collect();
            let v: f64 = s
                .parse()
                .map_err(|_| error(text, col, format!("`{s}` is not a number")))?;
            out.push((Token::Num(v), col));
            continue;
        }
        if c.is_alphabetic() || c == '_' {
            let start = i;
            while i < chars.len() && (chars[i].is_alphanumeric() || chars[i] == '_') {
                i += 1;
            }
            out.push((Token::Name(chars[start..i].iter().collect()), col));
            continue;
        }
        let t = match c {
            '*' if chars.get(i + 1) == Some(&'*') => {
                i += 1;
                Token::Pow
            }
            '+' | '-' | '*' | '/' | '^' => Token::Op(c),
            ',' => Token::Comma,
            '(' => Token::Open,
            ')' => Token::Close,
            _ => {
                return Err(error(
                    text,
                    col,
                    format!("unexpected character `{c}` (an energy uses numbers, names, + − * / ^, parentheses and the functions {FUNCTIONS})"),
                ))
            }
        };
        out.push((t, col));
        i += 1;
    }
    out.push((Token::End, chars.len() + 1));
    Ok(out)
}

impl Parser<'_> {
    fn peek(&self) -> &Token {
        &self.tokens[self.pos].0
    }
    fn column(&self) -> usize {
        self.tokens[self.pos].1
    }
    fn next(&mut self) -> (Token, usize) {
        let t = self.tokens[self.pos].clone();
        if self.pos + 1 < self.tokens.len() {
            self.pos += 1;
        }
        t
    }
    fn push(&mut self, n: Node) -> usize {
        // fold constants as they are built
        let c = |k: usize, nodes: &[Node]| match nodes[k] {
            Node::Const(v) => Some(v),
            _ => None,
        };
        let folded = match n {
            Node::Neg(a) => c(a, &self.nodes).map(|x| -x),
            Node::Add(a, b) => c(a, &self.nodes).zip(c(b, &self.nodes)).map(|(x, y)| x + y),
            Node::Sub(a, b) => c(a, &self.nodes).zip(c(b, &self.nodes)).map(|(x, y)| x - y),
            Node::Mul(a, b) => c(a, &self.nodes).zip(c(b, &self.nodes)).map(|(x, y)| x * y),
            Node::Div(a, b) => c(a, &self.nodes).zip(c(b, &self.nodes)).map(|(x, y)| x / y),
            Node::PowI(a, n) => c(a, &self.nodes).map(|x| x.powi(n)),
            Node::PowF(a, p) => c(a, &self.nodes).map(|x| x.powf(p)),
            Node::Call(f, a) => c(a, &self.nodes).map(|x| f.apply(x)),
            _ => None,
        };
        self.nodes.push(folded.map_or(n, Node::Const));
        self.nodes.len() - 1
    }
    /// Whether the energy has grown past [`MAX_NODES`] operations.
    fn too_many(&self) -> Result<(), MaterialError> {
        if self.nodes.len() > MAX_NODES {
            let col = self.column();
            return Err(error(
                self.text,
                col,
                format!("the energy has more than {MAX_NODES} operations (an energy is a formula, not data)"),
            ));
        }
        Ok(())
    }
    fn expect_close(&mut self, open_col: usize) -> Result<(), MaterialError> {
        match self.next() {
            (Token::Close, _) => Ok(()),
            (_, col) => Err(error(
                self.text,
                col,
                format!("expected `)` to close the `(` at column {open_col}"),
            )),
        }
    }
    fn expr(&mut self) -> Result<usize, MaterialError> {
        let mut left = self.term()?;
        loop {
            match self.peek() {
                Token::Op('+') => {
                    self.next();
                    let r = self.term()?;
                    left = self.push(Node::Add(left, r));
                    self.too_many()?;
                }
                Token::Op('-') => {
                    self.next();
                    let r = self.term()?;
                    left = self.push(Node::Sub(left, r));
                }
                _ => return Ok(left),
            }
        }
    }
    fn term(&mut self) -> Result<usize, MaterialError> {
        let mut left = self.unary()?;
        loop {
            match self.peek() {
                Token::Op('*') => {
                    self.next();
                    let r = self.unary()?;
                    left = self.push(Node::Mul(left, r));
                    self.too_many()?;
                }
                Token::Op('/') => {
                    self.next();
                    let r = self.unary()?;
                    left = self.push(Node::Div(left, r));
                }
                _ => return Ok(left),
            }
        }
    }
    /// One level of nesting: every recursion of the parser passes here (a sign, a
    /// parenthesis's expression, an exponent, a call's arguments), so the depth is bounded.
    fn unary(&mut self) -> Result<usize, MaterialError> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            let col = self.column();
            return Err(error(
                self.text,
                col,
                format!("the energy nests deeper than {MAX_DEPTH} levels (parentheses, signs, exponents, calls) here"),
            ));
        }
        let r = self.unary_inner();
        self.depth -= 1;
        r
    }
    fn unary_inner(&mut self) -> Result<usize, MaterialError> {
        match self.peek() {
            Token::Op('-') => {
                self.next();
                let a = self.unary()?;
                Ok(self.push(Node::Neg(a)))
            }
            Token::Op('+') => {
                self.next();
                self.unary()
            }
            _ => self.power(),
        }
    }
    fn power(&mut self) -> Result<usize, MaterialError> {
        let base = self.atom()?;
        if matches!(self.peek(), Token::Op('^') | Token::Pow) {
            self.next();
            let e = self.unary()?;
            return Ok(self.pow(base, e));
        }
        Ok(base)
    }
    fn pow(&mut self, base: usize, e: usize) -> usize {
        match self.nodes[e] {
            // x^0 = 1 everywhere, with zero derivatives (through powi its derivative would be
            // 0 · x⁻¹, NaN at x = 0)
            Node::Const(0.0) => self.push(Node::Const(1.0)),
            Node::Const(p) if p == p.trunc() && p.abs() <= 64.0 => {
                self.push(Node::PowI(base, p as i32))
            }
            Node::Const(p) => self.push(Node::PowF(base, p)),
            _ => self.push(Node::Pow(base, e)),
        }
    }
    fn atom(&mut self) -> Result<usize, MaterialError> {
        let (tok, col) = self.next();
        match tok {
            Token::Num(v) => Ok(self.push(Node::Const(v))),
            Token::Open => {
                let e = self.expr()?;
                self.expect_close(col)?;
                Ok(e)
            }
            Token::Name(name) => {
                if matches!(self.peek(), Token::Open) {
                    let open = self.column();
                    self.next();
                    return self.call(&name, col, open);
                }
                if let Some(k) = self.variables.iter().position(|v| *v == name) {
                    return Ok(self.push(Node::Var(k)));
                }
                if let Some(&v) = self.parameters.get(&name) {
                    return Ok(self.push(Node::Const(v)));
                }
                Err(error(self.text, col, self.unknown(&name)))
            }
            Token::End => Err(error(
                self.text,
                col,
                "the expression ends where a number, a name or `(` was expected".into(),
            )),
            t => Err(error(
                self.text,
                col,
                format!(
                    "expected a number, a name or `(`, found `{}`",
                    match t {
                        Token::Op(c) => c.to_string(),
                        Token::Pow => "**".into(),
                        Token::Comma => ",".into(),
                        Token::Close => ")".into(),
                        _ => String::new(),
                    }
                ),
            )),
        }
    }
    fn unknown(&self, name: &str) -> String {
        let params: Vec<&str> = self.parameters.keys().map(String::as_str).collect();
        format!(
            "unknown name `{name}`: the variables are {}{}",
            self.variables.join(", "),
            if params.is_empty() {
                " and the law has no parameters (give them in `parameters`)".to_string()
            } else {
                format!(", the parameters {}", params.join(", "))
            }
        )
    }
    fn call(&mut self, name: &str, col: usize, open: usize) -> Result<usize, MaterialError> {
        let mut args = vec![self.expr()?];
        while matches!(self.peek(), Token::Comma) {
            self.next();
            args.push(self.expr()?);
        }
        self.expect_close(open)?;
        let want = if name == "pow" { 2 } else { 1 };
        let f = match name {
            "ln" | "log" => Some(Func::Ln),
            "exp" => Some(Func::Exp),
            "sqrt" => Some(Func::Sqrt),
            "sinh" => Some(Func::Sinh),
            "cosh" => Some(Func::Cosh),
            "tanh" => Some(Func::Tanh),
            "pow" => None,
            _ => {
                return Err(error(
                    self.text,
                    col,
                    format!("unknown function `{name}` (the functions are {FUNCTIONS})"),
                ))
            }
        };
        if args.len() != want {
            return Err(error(
                self.text,
                col,
                format!("`{name}` takes {want} argument(s), not {}", args.len()),
            ));
        }
        Ok(match f {
            Some(f) => self.push(Node::Call(f, args[0])),
            None => self.pow(args[0], args[1]),
        })
    }
}

impl Func {
    fn apply<T: Real>(self, x: T) -> T {
        match self {
            Func::Ln => x.ln(),
            Func::Exp => x.exp(),
            Func::Sqrt => x.sqrt(),
            Func::Sinh => (x.exp() - (-x).exp()) * 0.5,
            Func::Cosh => (x.exp() + (-x).exp()) * 0.5,
            // through exp(−2|x|) ≤ 1, which cannot overflow (exp(2x) is inf above x ≈ 355)
            Func::Tanh if x.value() >= 0.0 => {
                let e = (x * -2.0).exp();
                (e * -1.0 + 1.0) / (e + 1.0)
            }
            Func::Tanh => {
                let e = (x * 2.0).exp();
                (e - 1.0) / (e + 1.0)
            }
        }
    }
}

impl Expr {
    /// Parse `text`, in which the names of `variables` are the arguments of [`Expr::eval`] and
    /// those of `parameters` are constants.
    pub fn parse(
        text: &str,
        variables: &[&str],
        parameters: &BTreeMap<String, f64>,
    ) -> Result<Self, MaterialError> {
        for (name, v) in parameters {
            if variables.contains(&name.as_str()) {
                return Err(MaterialError::Parameter {
                    name: name.as_str().into(),
                    value: *v,
                    requirement: format!(
                        "a parameter may not be named as a variable ({})",
                        variables.join(", ")
                    )
                    .into(),
                });
            }
            if !v.is_finite() {
                return Err(MaterialError::Parameter {
                    name: name.as_str().into(),
                    value: *v,
                    requirement: "a parameter must be a finite number".into(),
                });
            }
        }
        if text.trim().is_empty() {
            return Err(error(text, 1, "the energy is empty".into()));
        }
        let mut p = Parser {
            tokens: tokenize(text)?,
            pos: 0,
            depth: 0,
            nodes: vec![],
            variables,
            parameters,
            text,
        };
        let root = p.expr()?;
        if !matches!(p.peek(), Token::End) {
            let col = p.column();
            return Err(error(
                text,
                col,
                "unexpected text after a complete expression (an operator missing?)".into(),
            ));
        }
        p.too_many()?;
        Ok(Expr {
            nodes: tape(&p.nodes, root),
            text: text.to_string(),
            variables: variables.iter().map(|v| v.to_string()).collect(),
        })
    }

    /// The text it was parsed from.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// Whether the expression names variable `k`.
    pub fn uses(&self, k: usize) -> bool {
        self.nodes.contains(&Node::Var(k))
    }

    /// The value at `vars` (one per variable, in the order given to [`Expr::parse`]): the
    /// tape evaluated in order, each operation once, without recursion (an operation's
    /// operands come before it), so a sum of 20,000 terms costs 20,000 operations and no
    /// stack.
    pub fn eval<T: Real>(&self, vars: &[T]) -> T {
        let mut val: Vec<T> = Vec::with_capacity(self.nodes.len());
        for n in &self.nodes {
            let x = match *n {
                Node::Const(c) => vars[0].lift(c),
                Node::Var(i) => vars[i],
                Node::Neg(a) => -val[a],
                Node::Add(a, b) => val[a] + val[b],
                Node::Sub(a, b) => val[a] - val[b],
                Node::Mul(a, b) => val[a] * val[b],
                Node::Div(a, b) => val[a] / val[b],
                Node::PowI(a, k) => val[a].powi(k),
                Node::PowF(a, p) => val[a].powf(p),
                Node::Pow(a, b) => val[a].pow(val[b]),
                Node::Call(f, a) => f.apply(val[a]),
            };
            val.push(x);
        }
        val[val.len() - 1]
    }
}

/// The operations `root` depends on, in an order where each comes after its operands, the
/// root last (the tape [`Expr::eval`] runs): the parser's arena without what constant folding
/// left unused. Walked with an explicit stack, so its depth is unbounded.
fn tape(nodes: &[Node], root: usize) -> Vec<Node> {
    let operands = |n: &Node| -> [Option<usize>; 2] {
        match *n {
            Node::Const(_) | Node::Var(_) => [None, None],
            Node::Neg(a) | Node::PowI(a, _) | Node::PowF(a, _) | Node::Call(_, a) => {
                [Some(a), None]
            }
            Node::Add(a, b)
            | Node::Sub(a, b)
            | Node::Mul(a, b)
            | Node::Div(a, b)
            | Node::Pow(a, b) => [Some(a), Some(b)],
        }
    };
    let mut live = vec![false; nodes.len()];
    let mut stack = vec![root];
    while let Some(k) = stack.pop() {
        if std::mem::replace(&mut live[k], true) {
            continue;
        }
        stack.extend(operands(&nodes[k]).into_iter().flatten());
    }
    // the arena is already in operand-before-operation order (a node is pushed after its
    // operands): keep the live nodes in it, renumbered
    let mut new_index = vec![usize::MAX; nodes.len()];
    let mut out = Vec::with_capacity(nodes.len());
    for (k, n) in nodes.iter().enumerate() {
        if !live[k] {
            continue;
        }
        let map = |i: usize| new_index[i];
        let m = match *n {
            Node::Neg(a) => Node::Neg(map(a)),
            Node::Add(a, b) => Node::Add(map(a), map(b)),
            Node::Sub(a, b) => Node::Sub(map(a), map(b)),
            Node::Mul(a, b) => Node::Mul(map(a), map(b)),
            Node::Div(a, b) => Node::Div(map(a), map(b)),
            Node::PowI(a, p) => Node::PowI(map(a), p),
            Node::PowF(a, p) => Node::PowF(map(a), p),
            Node::Pow(a, b) => Node::Pow(map(a), map(b)),
            Node::Call(f, a) => Node::Call(f, map(a)),
            c @ (Node::Const(_) | Node::Var(_)) => c,
        };
        new_index[k] = out.len();
        out.push(m);
    }
    // the root is the arena's largest live index (everything live is its operand, or it)
    debug_assert_eq!(new_index[root], out.len() - 1);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn params(p: &[(&str, f64)]) -> BTreeMap<String, f64> {
        p.iter().map(|(k, v)| (k.to_string(), *v)).collect()
    }

    #[test]
    fn expressions_evaluate_with_precedence_and_functions() {
        let p = params(&[("jm", 50.0), ("c", 2.0)]);
        let cases: &[(&str, f64)] = &[
            ("1 + 2 * 3", 7.0),
            ("(1 + 2) * 3", 9.0),
            ("2 ^ 3 ^ 2", 512.0),
            ("-2 ^ 2", -4.0),
            ("2 ** -1", 0.5),
            ("I1 / 2 - I2", 1.5 / 2.0 - 0.25),
            (
                "-(jm / 2) * ln(1 - (I1 - 3) / jm)",
                -25.0 * (1.0f64 - (1.5 - 3.0) / 50.0).ln(),
            ),
            ("pow(I1, c) + sqrt(4) + exp(0) + log(1)", 2.25 + 3.0),
            ("cosh(0.3)^2 - sinh(0.3)^2", 1.0),
            ("tanh(0.2)", 0.2f64.tanh()),
            ("tanh(400)", 1.0),
            ("tanh(-400)", -1.0),
            ("tanh(-0.2)", -(0.2f64.tanh())),
            ("(I1 - 1.5)^0 + I2^0", 2.0),
            ("1.5e1 + .5", 15.5),
            ("I1^0.5", 1.5f64.sqrt()),
        ];
        for (text, want) in cases {
            let e = Expr::parse(text, &["I1", "I2"], &p).unwrap();
            let got = e.eval(&[1.5, 0.25]);
            assert!(
                (got - want).abs() < 1e-14 * want.abs().max(1.0),
                "{text}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn bad_expressions_name_the_column_and_the_problem() {
        let p = params(&[("jm", 50.0)]);
        let cases: &[(&str, usize, &str)] = &[
            ("-(jn / 2) * ln(1 - (I1 - 3) / jm)", 3, "unknown name `jn`"),
            ("I1 +", 5, "ends where"),
            ("(I1 - 3", 8, "expected `)` to close the `(` at column 1"),
            ("I1 3", 4, "after a complete expression"),
            ("lg(I1)", 1, "unknown function `lg`"),
            ("pow(I1)", 1, "takes 2 argument"),
            ("I1 # 2", 4, "unexpected character `#`"),
            ("", 1, "empty"),
            ("i1 - 3", 1, "the variables are I1, I2, the parameters jm"),
        ];
        for (text, col, needle) in cases {
            let e = Expr::parse(text, &["I1", "I2"], &p).unwrap_err();
            let msg = e.to_string();
            assert!(msg.contains(needle), "{text}: {msg}");
            match e {
                MaterialError::Expression { column, .. } => assert_eq!(column, *col, "{text}"),
                other => panic!("{other:?}"),
            }
        }
        // a parameter named as a variable, or not finite
        assert!(Expr::parse("I1", &["I1", "I2"], &params(&[("I1", 1.0)])).is_err());
        assert!(Expr::parse("I1", &["I1", "I2"], &params(&[("a", f64::NAN)])).is_err());
    }

    /// Issue #61: energies that had overflowed the stack (exit 134) are parsed and evaluated
    /// without recursion, or refused with a short message: 100k nested parentheses and 100k
    /// unary minus signs pass [`MAX_DEPTH`]; a plain sum of 20,000 terms (200 KB) is a tape of
    /// 40,000 operations, evaluated to the exact sum; a 1000-term energy too; a message quotes
    /// at most 2 × 40 characters of the energy.
    #[test]
    fn deep_and_long_energies_are_refused_or_evaluated_without_recursion() {
        let p = BTreeMap::new();
        for text in [
            format!("{}I1{}", "(".repeat(100_000), ")".repeat(100_000)),
            format!("{}I1", "-".repeat(100_000)),
            format!("I1{}", "^2".repeat(100_000)),
        ] {
            let e = Expr::parse(&text, &["I1", "I2"], &p)
                .unwrap_err()
                .to_string();
            assert!(
                e.contains(&format!("deeper than {MAX_DEPTH}")),
                "{}",
                &e[..e.len().min(300)]
            );
            assert!(
                e.len() < 400,
                "the message echoes the energy: {} bytes",
                e.len()
            );
        }
        let n = 20_000;
        let sum = vec!["I1"; n].join(" + ");
        let e = Expr::parse(&sum, &["I1", "I2"], &p).unwrap();
        assert_eq!(e.eval(&[1.5, 0.0]), 1.5 * n as f64);
        // folded constants leave no dead operations on the tape
        let e = Expr::parse("2 * 3 + I1 * (4 - 4)", &["I1", "I2"], &p).unwrap();
        assert_eq!(e.nodes.len(), 5, "{:?}", e.nodes);
        assert_eq!(e.eval(&[7.0, 0.0]), 6.0);
        let too_long = vec!["I1"; MAX_NODES + 10].join(" + ");
        let e = Expr::parse(&too_long, &["I1", "I2"], &p)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("more than 100000 operations") && e.len() < 400,
            "{}",
            &e[..e.len().min(300)]
        );
    }
}
