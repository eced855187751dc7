//! Locates ARPACK-NG (>= 3.8, ISO C bindings) through pkg-config and links it.

const HINT: &str = "ARPACK not found: install it with `apt-get install -y libarpack2-dev pkg-config`";

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    if let Err(e) = pkg_config::Config::new()
        .atleast_version("3.8")
        .probe("arpack")
    {
        // One short diagnostic line (the probe error is several paragraphs long), then
        // the install hint, which is also the failure message.
        let first = e.to_string();
        let first = first.lines().next().unwrap_or_default().trim().to_string();
        if !first.is_empty() {
            println!("cargo:warning=pkg-config: {first}");
        }
        println!("cargo:warning={HINT}");
        panic!("{HINT}");
    }
}
