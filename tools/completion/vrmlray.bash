# bash completion for vrmlray. The options come from the binary's own --help, so they never drift from it.
_vrmlray() {
    local cur=${COMP_WORDS[COMP_CWORD]} sub=""
    local w
    for w in "${COMP_WORDS[@]:1:COMP_CWORD-1}"; do
        case "$w" in render|info|convert|compare|bench) sub=$w; break;; esac
    done
    if [ -z "$sub" ]; then
        COMPREPLY=($(compgen -W "render info convert compare bench --help --version" -- "$cur"))
        return
    fi
    if [[ "$cur" == -* ]]; then
        local opts
        opts=$("${COMP_WORDS[0]}" "$sub" --help 2>/dev/null | grep -Eo -- '(^|[ ,])--?[A-Za-z][-A-Za-z0-9]*' | tr -d ' ,' | sort -u)
        COMPREPLY=($(compgen -W "$opts" -- "$cur"))
        return
    fi
    case "$sub" in
        compare) COMPREPLY=($(compgen -f -X '!*.@(png|exr|hdr|tif|tiff|jpg|jpeg|ppm)' -- "$cur")) ;;
        *) COMPREPLY=($(compgen -f -X '!*.@(wrl|wrz|gz|x3d|x3dv|x3dz|x3dvz|png|exr|hdr|tif|ppm|jpg)' -- "$cur")) ;;
    esac
    compopt -o plusdirs 2>/dev/null
}
complete -F _vrmlray vrmlray
