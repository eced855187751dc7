//! Coefficient formulas of parametric operators: a tiny expression language in one
//! named parameter.
//!
//! Grammar (usual precedence, `^` right-associative and above unary minus, so
//! `-W^2 = -(W^2)` and `2^-1 = 0.5`):
//!
//! ```text
//! expr   = term   (("+" | "-") term)*
//! term   = unary  (("*" | "/") unary)*
//! unary  = ("+" | "-") unary | power
//! power  = atom   ("^" unary)?
//! atom   = number | name | "(" expr ")"
//! ```
//!
//! Numbers are decimal with an optional exponent (`2`, `0.5`, `1e-3`, `.5E+2`); the only
//! name is the parameter's. Evaluation is plain `f64` arithmetic: `1/W` at `W = 0` is
//! infinite, and the caller decides what a non-finite coefficient means.

/// A parsed formula.
#[derive(Debug, Clone, PartialEq)]
pub struct Expr(Node);

#[derive(Debug, Clone, PartialEq)]
enum Node {
    Num(f64),
    Param,
    Neg(Box<Node>),
    Bin(Op, Box<Node>, Box<Node>),
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Op {
    Add,
    Sub,
    Mul,
    Div,
    Pow,
}

impl Expr {
    /// A constant.
    pub fn constant(value: f64) -> Self {
        Expr(Node::Num(value))
    }

    /// Parses `text`, whose only name may be `parameter` (`None`: no name allowed).
    ///
    /// # Errors
    /// A one-line message saying what is wrong and where (0-based character position).
    pub fn parse(text: &str, parameter: Option<&str>) -> Result<Self, String> {
        let mut p = Parser {
            s: text.as_bytes(),
            text,
            pos: 0,
            parameter,
        };
        let node = p.expr()?;
        p.skip_ws();
        if p.pos < p.s.len() {
            return Err(format!(
                "unexpected `{}` at position {} of `{text}`",
                &text[p.pos..],
                p.pos
            ));
        }
        Ok(Expr(node))
    }

    /// The value at `parameter = value`.
    pub fn eval(&self, value: f64) -> f64 {
        fn go(n: &Node, x: f64) -> f64 {
            match n {
                Node::Num(v) => *v,
                Node::Param => x,
                Node::Neg(a) => -go(a, x),
                Node::Bin(op, a, b) => {
                    let (a, b) = (go(a, x), go(b, x));
                    match op {
                        Op::Add => a + b,
                        Op::Sub => a - b,
                        Op::Mul => a * b,
                        Op::Div => a / b,
                        Op::Pow => a.powf(b),
                    }
                }
            }
        }
        go(&self.0, value)
    }

    /// Whether the formula uses the parameter.
    pub fn uses_parameter(&self) -> bool {
        fn go(n: &Node) -> bool {
            match n {
                Node::Num(_) => false,
                Node::Param => true,
                Node::Neg(a) => go(a),
                Node::Bin(_, a, b) => go(a) || go(b),
            }
        }
        go(&self.0)
    }
}

struct Parser<'a> {
    s: &'a [u8],
    text: &'a str,
    pos: usize,
    parameter: Option<&'a str>,
}

impl Parser<'_> {
    fn skip_ws(&mut self) {
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.s.get(self.pos).copied()
    }

    fn expr(&mut self) -> Result<Node, String> {
        let mut a = self.term()?;
        while let Some(c @ (b'+' | b'-')) = self.peek() {
            self.pos += 1;
            let b = self.term()?;
            let op = if c == b'+' { Op::Add } else { Op::Sub };
            a = Node::Bin(op, Box::new(a), Box::new(b));
        }
        Ok(a)
    }

    fn term(&mut self) -> Result<Node, String> {
        let mut a = self.unary()?;
        while let Some(c @ (b'*' | b'/')) = self.peek() {
            self.pos += 1;
            let b = self.unary()?;
            let op = if c == b'*' { Op::Mul } else { Op::Div };
            a = Node::Bin(op, Box::new(a), Box::new(b));
        }
        Ok(a)
    }

    fn unary(&mut self) -> Result<Node, String> {
        match self.peek() {
            Some(b'-') => {
                self.pos += 1;
                Ok(Node::Neg(Box::new(self.unary()?)))
            }
            Some(b'+') => {
                self.pos += 1;
                self.unary()
            }
            _ => self.power(),
        }
    }

    fn power(&mut self) -> Result<Node, String> {
        let a = self.atom()?;
        if self.peek() == Some(b'^') {
            self.pos += 1;
            let b = self.unary()?;
            return Ok(Node::Bin(Op::Pow, Box::new(a), Box::new(b)));
        }
        Ok(a)
    }

    fn atom(&mut self) -> Result<Node, String> {
        let text = self.text;
        match self.peek() {
            None => Err(format!(
                "`{text}` ends where a number, name or `(` is expected"
            )),
            Some(b'(') => {
                self.pos += 1;
                let e = self.expr()?;
                if self.peek() != Some(b')') {
                    return Err(format!("missing `)` at position {} of `{text}`", self.pos));
                }
                self.pos += 1;
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => {
                let start = self.pos;
                while self.pos < self.s.len()
                    && (self.s[self.pos].is_ascii_digit() || self.s[self.pos] == b'.')
                {
                    self.pos += 1;
                }
                if self.pos < self.s.len() && matches!(self.s[self.pos], b'e' | b'E') {
                    let save = self.pos;
                    self.pos += 1;
                    if self.pos < self.s.len() && matches!(self.s[self.pos], b'+' | b'-') {
                        self.pos += 1;
                    }
                    let digits = self.pos;
                    while self.pos < self.s.len() && self.s[self.pos].is_ascii_digit() {
                        self.pos += 1;
                    }
                    if self.pos == digits {
                        self.pos = save; // `2e` is not an exponent
                    }
                }
                let lit = &text[start..self.pos];
                lit.parse::<f64>()
                    .map(Node::Num)
                    .map_err(|_| format!("`{lit}` at position {start} of `{text}` is not a number"))
            }
            Some(c) if c.is_ascii_alphabetic() || c == b'_' => {
                let start = self.pos;
                while self.pos < self.s.len()
                    && (self.s[self.pos].is_ascii_alphanumeric() || self.s[self.pos] == b'_')
                {
                    self.pos += 1;
                }
                let name = &text[start..self.pos];
                match self.parameter {
                    Some(p) if p == name => Ok(Node::Param),
                    Some(p) => Err(format!(
                        "unknown name `{name}` in `{text}`; the parameter is `{p}`"
                    )),
                    None => Err(format!(
                        "name `{name}` in `{text}`, but the operator declares no `parameter`"
                    )),
                }
            }
            Some(c) => Err(format!(
                "unexpected `{}` at position {} of `{text}`",
                c as char, self.pos
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ev(s: &str, w: f64) -> f64 {
        Expr::parse(s, Some("W")).unwrap().eval(w)
    }

    #[test]
    fn precedence_and_associativity() {
        assert_eq!(ev("1 + 2 * 3", 0.0), 7.0);
        assert_eq!(ev("(1 + 2) * 3", 0.0), 9.0);
        assert_eq!(ev("2 ^ 3 ^ 2", 0.0), 512.0);
        assert_eq!(ev("-W^2", 3.0), -9.0);
        assert_eq!(ev("2^-1", 0.0), 0.5);
        assert_eq!(ev("1/W", 4.0), 0.25);
        assert_eq!(ev("W/2/2", 8.0), 2.0);
        assert_eq!(ev("10 - 4 - 3", 0.0), 3.0);
        assert_eq!(ev("(W/100)^2 - 1.5e-1*W + .5E+1", 10.0), 0.01 - 1.5 + 5.0);
        assert_eq!(ev("3", 7.0), 3.0);
        assert!(ev("1/W", 0.0).is_infinite());
        assert!(Expr::parse("W^2", Some("W")).unwrap().uses_parameter());
        assert!(!Expr::parse("2*3", Some("W")).unwrap().uses_parameter());
    }

    #[test]
    fn errors_say_what_and_where() {
        for (s, want) in [
            ("V^2", "unknown name `V`"),
            ("2 *", "ends where"),
            ("(W + 1", "missing `)`"),
            ("W W", "unexpected `W`"),
            ("2 # 3", "unexpected `# 3` at position 2"),
            ("1..2", "not a number"),
        ] {
            let e = Expr::parse(s, Some("W")).unwrap_err();
            assert!(e.contains(want), "{s}: {e}");
        }
        let e = Expr::parse("W", None).unwrap_err();
        assert!(e.contains("declares no `parameter`"), "{e}");
    }
}
