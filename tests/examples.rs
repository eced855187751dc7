//! The examples that teach the library run to the end: a change of the library's API or
//! behaviour that breaks one fails here, not in a user's first hour. (`custom_basis` is
//! exercised by `tests/bench.rs`.)

#[path = "../examples/uniform_contact.rs"]
mod uniform_contact;

#[path = "../examples/imported_operator.rs"]
mod imported_operator;

#[test]
fn uniform_contact_runs() {
    if let Err(e) = uniform_contact::main() {
        panic!("examples/uniform_contact.rs: {e}");
    }
}

#[test]
fn imported_operator_runs() {
    if let Err(e) = imported_operator::main() {
        panic!("examples/imported_operator.rs: {e}");
    }
}
