//! Closed-form scalar expressions of generalized coordinates and time, written by the user as
//! text (`"0.3 - L * sin(swing)"`) and evaluated by the engine on any `DualNum` scalar, so that
//! one evaluation on dual numbers gives exact derivatives (the Jacobians and the velocity-product
//! terms of a user gap function, [`crate::contact::gap`]).
//!
//! Grammar (usual precedence, `^` and `**` right-associative and above unary minus, so
//! `-x^2 = -(x^2)`): numbers (`1`, `2.5e-3`), the constants `pi` and `e`, the time `t`, variables
//! (a name, or `name[k]` for coordinate k of a multi-coordinate joint, resolved by the caller),
//! `+ - * / ^ **`, parentheses and the functions `sin cos tan asin acos atan sinh cosh tanh exp
//! ln log sqrt abs` of one argument and `atan2(y, x) hypot(x, y) min(a, b) max(a, b)`.
//!
//! The parsed form is a postfix program: evaluation is a loop over it with a value stack that
//! the caller keeps (no allocation once its capacity has grown to [`Expr::stack_len`]).

use num_dual::DualNum;

/// A function of one argument.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum F1 {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Sinh,
    Cosh,
    Tanh,
    Exp,
    Ln,
    Sqrt,
    Abs,
}

/// A function of two arguments.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum F2 {
    Atan2,
    Hypot,
    Min,
    Max,
}

/// One instruction of the postfix program.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Op {
    Const(f64),
    Var(usize),
    Time,
    Neg,
    Add,
    Sub,
    Mul,
    Div,
    /// `x ^ c` with a constant exponent (integer exponents by repeated products).
    PowConst(f64),
    Pow,
    Call1(F1),
    Call2(F2),
}

/// A parsed expression.
#[derive(Debug, Clone, PartialEq)]
pub struct Expr {
    text: String,
    ops: Vec<Op>,
    stack: usize,
    uses_time: bool,
}

#[derive(Debug, Clone, PartialEq)]
enum Token {
    Num(f64),
    Name(String),
    Sym(char),
    Pow,
    End,
}

struct Lexer<'a> {
    s: &'a [u8],
    pos: usize,
}

impl Lexer<'_> {
    /// The next token and the byte offset where it starts.
    fn next(&mut self) -> Result<(Token, usize), String> {
        while self.pos < self.s.len() && self.s[self.pos].is_ascii_whitespace() {
            self.pos += 1;
        }
        let start = self.pos;
        let Some(&c) = self.s.get(self.pos) else { return Ok((Token::End, start)) };
        if c.is_ascii_digit() || c == b'.' {
            let mut end = self.pos;
            while end < self.s.len() && (self.s[end].is_ascii_digit() || self.s[end] == b'.') {
                end += 1;
            }
            // an exponent: e or E, an optional sign, digits
            if end < self.s.len() && (self.s[end] == b'e' || self.s[end] == b'E') {
                let mut k = end + 1;
                if k < self.s.len() && (self.s[k] == b'+' || self.s[k] == b'-') {
                    k += 1;
                }
                if k < self.s.len() && self.s[k].is_ascii_digit() {
                    while k < self.s.len() && self.s[k].is_ascii_digit() {
                        k += 1;
                    }
                    end = k;
                }
            }
            let text = std::str::from_utf8(&self.s[start..end]).unwrap_or("");
            let v: f64 = text.parse().map_err(|_| format!("'{text}' at position {} is not a number", start + 1))?;
            self.pos = end;
            return Ok((Token::Num(v), start));
        }
        if c.is_ascii_alphabetic() || c == b'_' {
            let mut end = self.pos;
            while end < self.s.len() && (self.s[end].is_ascii_alphanumeric() || self.s[end] == b'_') {
                end += 1;
            }
            self.pos = end;
            return Ok((Token::Name(String::from_utf8_lossy(&self.s[start..end]).into_owned()), start));
        }
        if c == b'*' && self.s.get(self.pos + 1) == Some(&b'*') {
            self.pos += 2;
            return Ok((Token::Pow, start));
        }
        if b"+-*/^()[],".contains(&c) {
            self.pos += 1;
            return Ok((if c == b'^' { Token::Pow } else { Token::Sym(c as char) }, start));
        }
        let ch = std::str::from_utf8(&self.s[start..]).ok().and_then(|s| s.chars().next()).unwrap_or('?');
        Err(format!("unexpected character '{ch}' at position {}", start + 1))
    }
}

/// Recursive-descent parser emitting postfix code.
struct Parser<'a, R> {
    lex: Lexer<'a>,
    tok: Token,
    at: usize,
    ops: Vec<Op>,
    resolve: R,
}

impl<R: FnMut(&str, Option<usize>) -> Result<usize, String>> Parser<'_, R> {
    fn bump(&mut self) -> Result<(), String> {
        let (t, at) = self.lex.next()?;
        self.tok = t;
        self.at = at;
        Ok(())
    }

    fn describe(&self) -> String {
        match &self.tok {
            Token::End => "the end".to_string(),
            Token::Num(v) => format!("'{v}' at position {}", self.at + 1),
            Token::Name(n) => format!("'{n}' at position {}", self.at + 1),
            Token::Sym(c) => format!("'{c}' at position {}", self.at + 1),
            Token::Pow => format!("'^' at position {}", self.at + 1),
        }
    }

    fn expect(&mut self, c: char) -> Result<(), String> {
        if self.tok == Token::Sym(c) {
            self.bump()
        } else {
            Err(format!("expected '{c}', found {}", self.describe()))
        }
    }

    /// sum := term (('+' | '-') term)*
    fn sum(&mut self) -> Result<(), String> {
        self.term()?;
        loop {
            let op = match self.tok {
                Token::Sym('+') => Op::Add,
                Token::Sym('-') => Op::Sub,
                _ => return Ok(()),
            };
            self.bump()?;
            self.term()?;
            self.ops.push(op);
        }
    }

    /// term := unary (('*' | '/') unary)*
    fn term(&mut self) -> Result<(), String> {
        self.unary()?;
        loop {
            let op = match self.tok {
                Token::Sym('*') => Op::Mul,
                Token::Sym('/') => Op::Div,
                _ => return Ok(()),
            };
            self.bump()?;
            self.unary()?;
            self.ops.push(op);
        }
    }

    /// unary := ('-' | '+') unary | power
    fn unary(&mut self) -> Result<(), String> {
        match self.tok {
            Token::Sym('-') => {
                self.bump()?;
                self.unary()?;
                self.ops.push(Op::Neg);
                Ok(())
            }
            Token::Sym('+') => {
                self.bump()?;
                self.unary()
            }
            _ => self.power(),
        }
    }

    /// power := atom ('^' unary)?   (right-associative: the exponent may itself be a power)
    fn power(&mut self) -> Result<(), String> {
        self.atom()?;
        if self.tok == Token::Pow {
            self.bump()?;
            let mark = self.ops.len();
            self.unary()?;
            // a constant exponent (possibly negated) folds into one instruction
            let c = match &self.ops[mark..] {
                [Op::Const(c)] => Some(*c),
                [Op::Const(c), Op::Neg] => Some(-*c),
                _ => None,
            };
            match c {
                Some(c) => {
                    self.ops.truncate(mark);
                    self.ops.push(Op::PowConst(c));
                }
                None => self.ops.push(Op::Pow),
            }
        }
        Ok(())
    }

    fn atom(&mut self) -> Result<(), String> {
        match self.tok.clone() {
            Token::Num(v) => {
                self.ops.push(Op::Const(v));
                self.bump()
            }
            Token::Sym('(') => {
                self.bump()?;
                self.sum()?;
                self.expect(')')
            }
            Token::Name(name) => {
                let at = self.at;
                self.bump()?;
                if self.tok == Token::Sym('(') {
                    return self.call(&name, at);
                }
                match name.as_str() {
                    "pi" => self.ops.push(Op::Const(std::f64::consts::PI)),
                    "e" => self.ops.push(Op::Const(std::f64::consts::E)),
                    "t" => self.ops.push(Op::Time),
                    _ => {
                        let index = if self.tok == Token::Sym('[') {
                            self.bump()?;
                            let k = match self.tok {
                                Token::Num(v) if v >= 0.0 && v.fract() == 0.0 && v < 1e6 => v as usize,
                                _ => return Err(format!("expected a coordinate index after '{name}[', found {}", self.describe())),
                            };
                            self.bump()?;
                            self.expect(']')?;
                            Some(k)
                        } else {
                            None
                        };
                        let slot = (self.resolve)(&name, index).map_err(|m| format!("{m} (position {})", at + 1))?;
                        self.ops.push(Op::Var(slot));
                    }
                }
                Ok(())
            }
            _ => Err(format!("expected a number, a name or '(', found {}", self.describe())),
        }
    }

    fn call(&mut self, name: &str, at: usize) -> Result<(), String> {
        let one = match name {
            "sin" => Some(F1::Sin),
            "cos" => Some(F1::Cos),
            "tan" => Some(F1::Tan),
            "asin" => Some(F1::Asin),
            "acos" => Some(F1::Acos),
            "atan" => Some(F1::Atan),
            "sinh" => Some(F1::Sinh),
            "cosh" => Some(F1::Cosh),
            "tanh" => Some(F1::Tanh),
            "exp" => Some(F1::Exp),
            "ln" | "log" => Some(F1::Ln),
            "sqrt" => Some(F1::Sqrt),
            "abs" => Some(F1::Abs),
            _ => None,
        };
        let two = match name {
            "atan2" => Some(F2::Atan2),
            "hypot" => Some(F2::Hypot),
            "min" => Some(F2::Min),
            "max" => Some(F2::Max),
            _ => None,
        };
        if one.is_none() && two.is_none() {
            return Err(format!(
                "unknown function '{name}' at position {} (known: sin, cos, tan, asin, acos, atan, sinh, cosh, tanh, \
                 exp, ln, log, sqrt, abs, atan2, hypot, min, max)",
                at + 1
            ));
        }
        self.expect('(')?;
        self.sum()?;
        if let Some(f) = two {
            self.expect(',')?;
            self.sum()?;
            self.expect(')')?;
            self.ops.push(Op::Call2(f));
        } else {
            if self.tok == Token::Sym(',') {
                return Err(format!("'{name}' at position {} takes one argument", at + 1));
            }
            self.expect(')')?;
            self.ops.push(Op::Call1(one.expect("a one-argument function")));
        }
        Ok(())
    }
}

impl Expr {
    /// Parses `text`; `resolve(name, index)` turns a variable (`name` or `name[index]`) into a
    /// slot of the variable array that [`Expr::eval`] is given, or says why it cannot. The error
    /// says what is wrong and where (1-based character position).
    pub fn parse(text: &str, resolve: impl FnMut(&str, Option<usize>) -> Result<usize, String>) -> Result<Expr, String> {
        let mut p = Parser { lex: Lexer { s: text.as_bytes(), pos: 0 }, tok: Token::End, at: 0, ops: Vec::new(), resolve };
        p.bump()?;
        if p.tok == Token::End {
            return Err("the expression is empty".to_string());
        }
        p.sum()?;
        if p.tok != Token::End {
            return Err(format!("unexpected {} (an operator missing?)", p.describe()));
        }
        // the largest stack depth the program reaches
        let (mut depth, mut stack) = (0usize, 0usize);
        for op in &p.ops {
            match op {
                Op::Const(_) | Op::Var(_) | Op::Time => depth += 1,
                Op::Add | Op::Sub | Op::Mul | Op::Div | Op::Pow | Op::Call2(_) => depth -= 1,
                Op::Neg | Op::PowConst(_) | Op::Call1(_) => {}
            }
            stack = stack.max(depth);
        }
        let uses_time = p.ops.contains(&Op::Time);
        Ok(Expr { text: text.to_string(), ops: p.ops, stack, uses_time })
    }

    /// The text it was parsed from.
    pub fn text(&self) -> &str {
        &self.text
    }

    /// The stack depth [`Expr::eval`] needs.
    pub fn stack_len(&self) -> usize {
        self.stack
    }

    /// Whether the expression depends on time explicitly.
    pub fn uses_time(&self) -> bool {
        self.uses_time
    }

    /// The variable slots it reads (ascending, each once).
    pub fn slots(&self) -> Vec<usize> {
        let mut s: Vec<usize> = self.ops.iter().filter_map(|o| if let Op::Var(k) = o { Some(*k) } else { None }).collect();
        s.sort_unstable();
        s.dedup();
        s
    }

    /// The value at variables `vars` (by slot) and time `t`, on any dual scalar; `stack` is
    /// scratch (cleared here, grown only the first time).
    pub fn eval<D: DualNum<f64> + Copy>(&self, vars: &[D], t: D, stack: &mut Vec<D>) -> D {
        stack.clear();
        for op in &self.ops {
            let v = match *op {
                Op::Const(c) => D::from(c),
                Op::Var(k) => vars[k],
                Op::Time => t,
                Op::Neg => -stack.pop().expect("operand"),
                Op::PowConst(c) => {
                    let x = stack.pop().expect("operand");
                    if c.fract() == 0.0 && c.abs() <= 64.0 {
                        x.powi(c as i32)
                    } else {
                        x.powf(c)
                    }
                }
                Op::Call1(f) => {
                    let x = stack.pop().expect("operand");
                    match f {
                        F1::Sin => x.sin(),
                        F1::Cos => x.cos(),
                        F1::Tan => x.tan(),
                        F1::Asin => x.asin(),
                        F1::Acos => x.acos(),
                        F1::Atan => x.atan(),
                        F1::Sinh => x.sinh(),
                        F1::Cosh => x.cosh(),
                        F1::Tanh => x.tanh(),
                        F1::Exp => x.exp(),
                        F1::Ln => x.ln(),
                        F1::Sqrt => x.sqrt(),
                        // the derivative of |x| is sign(x) (the kink at 0 taken as +)
                        F1::Abs => {
                            if x.re() < 0.0 {
                                -x
                            } else {
                                x
                            }
                        }
                    }
                }
                _ => {
                    let b = stack.pop().expect("operand");
                    let a = stack.pop().expect("operand");
                    match *op {
                        Op::Add => a + b,
                        Op::Sub => a - b,
                        Op::Mul => a * b,
                        Op::Div => a / b,
                        Op::Pow => a.powd(b),
                        Op::Call2(F2::Atan2) => a.atan2(b),
                        Op::Call2(F2::Hypot) => (a * a + b * b).sqrt(),
                        Op::Call2(F2::Min) => {
                            if b.re() < a.re() {
                                b
                            } else {
                                a
                            }
                        }
                        Op::Call2(F2::Max) => {
                            if b.re() > a.re() {
                                b
                            } else {
                                a
                            }
                        }
                        _ => unreachable!("binary operators only"),
                    }
                }
            };
            stack.push(v);
        }
        stack.pop().expect("a parsed expression leaves one value")
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_dual::{Dual2_64, Dual64};

    fn vars(names: &'static [&'static str]) -> impl FnMut(&str, Option<usize>) -> Result<usize, String> {
        move |n, k| match (names.iter().position(|x| *x == n), k) {
            (Some(i), None) => Ok(i),
            (Some(_), Some(k)) => Err(format!("'{n}' has one coordinate, [{k}] given")),
            (None, _) => Err(format!("unknown coordinate '{n}'")),
        }
    }

    fn value(text: &str, x: &[f64], t: f64) -> f64 {
        let e = Expr::parse(text, vars(&["x", "y"])).unwrap();
        e.eval(x, t, &mut Vec::new())
    }

    #[test]
    fn precedence_and_associativity_follow_the_usual_rules() {
        let x = [2.0, 3.0];
        assert_eq!(value("1 + 2 * 3", &x, 0.0), 7.0);
        assert_eq!(value("(1 + 2) * 3", &x, 0.0), 9.0);
        assert_eq!(value("2 ^ 3 ^ 2", &x, 0.0), 512.0); // 2^(3^2)
        assert_eq!(value("2 ** 3", &x, 0.0), 8.0);
        assert_eq!(value("-x^2", &x, 0.0), -4.0);
        assert_eq!(value("x - y - 1", &x, 0.0), -2.0);
        assert_eq!(value("x / y / 2", &x, 0.0), 2.0 / 3.0 / 2.0);
        assert_eq!(value("2e-3 * 1E3 + .5", &x, 0.0), 2.5);
        assert_eq!(value("x^-1", &x, 0.0), 0.5);
        assert!((value("atan2(y, x) - atan(y / x)", &x, 0.0)).abs() < 1e-15);
        assert!((value("hypot(x, y)^2", &x, 0.0) - 13.0).abs() < 1e-14);
        assert_eq!(value("min(x, y) + max(x, y) * t", &x, 2.0), 8.0);
        assert!((value("sin(pi/6) + ln(e) + sqrt(abs(-y*3))", &x, 0.0) - 4.5).abs() < 1e-15);
    }

    #[test]
    fn dual_evaluation_gives_the_closed_form_derivatives() {
        // f = x² sin(y t) + exp(x/y): along x(τ) = x + a τ, y(τ) = y + b τ, t(τ) = t + τ
        let e = Expr::parse("x^2 * sin(y * t) + exp(x / y)", vars(&["x", "y"])).unwrap();
        assert!(e.uses_time());
        assert_eq!(e.slots(), vec![0, 1]);
        let (x, y, t, a, b) = (0.7, 1.3, 0.4, -0.5, 0.8);
        let d = [Dual2_64::new(x, a, 0.0), Dual2_64::new(y, b, 0.0)];
        let r = e.eval(&d, Dual2_64::new(t, 1.0, 0.0), &mut Vec::new());
        // closed forms with p = y t, ṗ = b t + y, p̈ = 2 b; s = x / y, ṡ = (a y - x b) / y², s̈ = d/dτ ṡ
        let (p, pd, pdd) = (y * t, b * t + y, 2.0 * b);
        let (s, sd) = (x / y, (a * y - x * b) / (y * y));
        let sdd = (-2.0 * a * b * y * y + 2.0 * x * b * b * y) / y.powi(4);
        let f = x * x * p.sin() + s.exp();
        let fd = 2.0 * x * a * p.sin() + x * x * p.cos() * pd + s.exp() * sd;
        let fdd = 2.0 * a * a * p.sin() + 4.0 * x * a * p.cos() * pd + x * x * (-p.sin() * pd * pd + p.cos() * pdd)
            + s.exp() * (sd * sd + sdd);
        assert!((r.re - f).abs() < 1e-14);
        assert!((r.v1 - fd).abs() < 1e-13, "{} vs {fd}", r.v1);
        assert!((r.v2 - fdd).abs() < 1e-12, "{} vs {fdd}", r.v2);
        // a gradient entry on first-order duals
        let g = e.eval(&[Dual64::new(x, 0.0), Dual64::new(y, 1.0)], Dual64::from(t), &mut Vec::new());
        let dfdy = x * x * p.cos() * t - x / (y * y) * s.exp();
        assert!((g.eps - dfdy).abs() < 1e-14);
    }

    #[test]
    fn constant_powers_fold_and_the_stack_depth_is_known() {
        let e = Expr::parse("(x + y)^2 - x^(-0.5) + 1", vars(&["x", "y"])).unwrap();
        assert!(e.ops.iter().any(|o| *o == Op::PowConst(2.0)) && e.ops.iter().any(|o| *o == Op::PowConst(-0.5)));
        assert!(!e.uses_time());
        let mut stack = Vec::new();
        let v = e.eval(&[4.0, 1.0], 0.0, &mut stack);
        assert_eq!(v, 25.0 - 0.5 + 1.0);
        assert_eq!(e.stack_len(), 2);
        assert!(stack.capacity() >= e.stack_len());
    }

    #[test]
    fn errors_say_what_and_where() {
        let err = |s: &str| Expr::parse(s, vars(&["x", "y"])).unwrap_err();
        assert_eq!(err(""), "the expression is empty");
        assert_eq!(err("x +"), "expected a number, a name or '(', found the end");
        assert_eq!(err("x y"), "unexpected 'y' at position 3 (an operator missing?)");
        assert_eq!(err("(x + 1"), "expected ')', found the end");
        assert_eq!(err("z * 2"), "unknown coordinate 'z' (position 1)");
        assert_eq!(err("2 * x[1]"), "'x' has one coordinate, [1] given (position 5)");
        assert!(err("sinus(x)").starts_with("unknown function 'sinus' at position 1"));
        assert_eq!(err("sin(x, y)"), "'sin' at position 1 takes one argument");
        assert_eq!(err("atan2(x)"), "expected ',', found ')' at position 8");
        assert_eq!(err("x # 2"), "unexpected character '#' at position 3");
        assert_eq!(err("1.2.3"), "'1.2.3' at position 1 is not a number");
        assert_eq!(err("x[-1]"), "expected a coordinate index after 'x[', found '-' at position 3");
    }
}
