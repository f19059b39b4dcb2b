//! `hil-sim`: the simulated drive on a PC.
fn main() {
    let cmd = std::env::args().nth(1).unwrap_or_else(|| "demo".into());
    match cmd.as_str() {
        "demo" => println!("hil-sim demo: the simulated ESC and drive arrive with issue 3"),
        other => {
            eprintln!("unknown command {other}; try `demo`");
            std::process::exit(2);
        }
    }
}
