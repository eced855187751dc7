//! Locates ARPACK-NG (>= 3.8, ISO C bindings) through pkg-config and links it.

const HINT: &str =
    "ARPACK not found: install it with `apt-get install -y libarpack2-dev pkg-config`";

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if let Err(e) = pkg_config::Config::new()
        .atleast_version("3.8")
        .probe("arpack")
    {
        // One short diagnostic line (the probe error is several paragraphs long: keep
        // pkg-config's own first complaint, e.g. "Package arpack was not found ..." or
        // "Requested 'arpack >= 3.8' but version of arpack is ..."), then the install
        // hint, which is also the failure message.
        let text = match &e {
            pkg_config::Error::Failure { output, .. }
            | pkg_config::Error::ProbeFailure { output, .. } => {
                String::from_utf8_lossy(&output.stderr).into_owned()
            }
            other => other.to_string(),
        };
        if let Some(first) = text.lines().map(str::trim).find(|l| !l.is_empty()) {
            println!("cargo:warning=pkg-config: {first}");
        }
        println!("cargo:warning={HINT}");
        panic!("{HINT}");
    }
}
