fn main() {
    println!("cargo::rustc-check-cfg=cfg(lucent_embree)");
}
