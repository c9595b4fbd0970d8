"""What the template generators share: write the template they generate, or, with
--check, say whether the file on disk is what they would write (CTest's
Templates.*_generated entries run them that way)."""


def write_or_check(path, text, generator, argv):
    """Writes `text` to the template `path`; with "--check" in `argv` writes nothing and
    returns 1 (saying so) when the file differs from `text`. `generator` is the script's
    path, named in the message. Returns the exit status."""
    if "--check" in argv:
        with open(path, encoding="utf-8") as stream:
            if stream.read() != text:
                print(f"{path} differs from what {generator} writes; run it to update")
                return 1
        print("up to date")
        return 0
    with open(path, "w", encoding="utf-8") as stream:
        stream.write(text)
    return 0
