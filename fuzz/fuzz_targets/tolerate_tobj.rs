//! `vstree::io::obj` runs the tobj crate inside `catch_unwind` on purpose: tobj 4 overflows
//! (and so panics, with overflow checks on, as in fuzz builds) on absurd relative face indices,
//! and the reader turns that into a parse error. libFuzzer's panic hook would abort on that
//! caught panic; this hook lets panics raised inside tobj through to the reader's
//! `catch_unwind` and hands every other panic to libFuzzer's hook, which reports it.

pub fn install() {
    let libfuzzer_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        let in_tobj = info.location().is_some_and(|l| l.file().contains("/tobj-"));
        if !in_tobj {
            libfuzzer_hook(info);
        }
    }));
}
