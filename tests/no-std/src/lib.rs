//! Proof that the generated mechanisms link without std: a `#![no_std]` staticlib with its own
//! panic handler. Build with `cargo build -p tests-no-std --config 'profile.dev.panic="abort"'`;
//! if anything pulls in std the build fails with a duplicate `panic_impl` lang item.
#![no_std]

#[panic_handler]
fn panic(_: &core::panic::PanicInfo) -> ! {
    loop {}
}
