//! `meshwork`: the HTTP job service (`meshwork serve`) and its command-line twin.

fn main() {
    faer::set_global_parallelism(faer::Par::Seq);
    println!("meshwork {}", env!("CARGO_PKG_VERSION"));
}
