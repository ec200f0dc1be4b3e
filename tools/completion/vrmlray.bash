# bash completion for vrmlray. The options, their value sets and which of them take a file come from the
# binary's own --help, so they never drift from it: an option shown as `--sampler TEXT:{center,grid,...}`
# completes to those words, one whose value is a FILE or DIR (`-o,--output FILE`) to paths, and any other
# value (a number, R,G,B, a name) to nothing rather than to unrelated file names.
_vrmlray() {
    local cur=${COMP_WORDS[COMP_CWORD]} prev=${COMP_WORDS[COMP_CWORD-1]} sub=""
    local w
    for w in "${COMP_WORDS[@]:1:COMP_CWORD-1}"; do
        case "$w" in render|info|convert|compare|bench) sub=$w; break;; esac
    done
    if [ -z "$sub" ]; then
        COMPREPLY=($(compgen -W "render info convert compare bench --help --version" -- "$cur"))
        return
    fi
    local help
    help=$("${COMP_WORDS[0]}" "$sub" --help 2>/dev/null)
    if [[ "$cur" == -* ]]; then
        local opts
        opts=$(grep -Eo -- '(^|[ ,])--?[A-Za-z][-A-Za-z0-9]*' <<<"$help" | tr -d ' ,' | sort -u)
        COMPREPLY=($(compgen -W "$opts" -- "$cur"))
        return
    fi
    if [[ "$prev" == -* ]]; then
        # The option's own line: "  -o,--output FILE   ..." or "  --sampler TEXT:{a,b}".
        local line type
        line=$(grep -E -- "^ +((-[A-Za-z],)?$prev|$prev,--[-A-Za-z0-9]+)( |$)" <<<"$help" | head -n 1)
        type=$(sed -E "s/^ +[^ ]+ //; s/ .*//" <<<"$line")
        if [[ -n "$line" && "$type" != "$line" && -n "$type" ]]; then
            if [[ "$type" =~ \{([^}]*)\} ]]; then
                COMPREPLY=($(compgen -W "${BASH_REMATCH[1]//,/ }" -- "$cur"))
            elif [[ "$type" == DIR* ]]; then
                COMPREPLY=($(compgen -d -- "$cur"))
            elif [[ "$type" == *FILE* ]]; then
                COMPREPLY=($(compgen -f -- "$cur"))
                compopt -o plusdirs 2>/dev/null
            else
                COMPREPLY=()
            fi
            return
        fi
    fi
    # The scene extensions as render's help lists them: "Scene file (.wrl .x3dv ..., each also + .gz)".
    local scenes
    scenes=$("${COMP_WORDS[0]}" render --help 2>/dev/null | sed -n 's/.*Scene file (\([^,]*\),.*/\1/p' |
        head -n 1 | sed 's/^\.//; s/ \./|/g')
    case "$sub" in
        compare) COMPREPLY=($(compgen -f -X '!*.@(png|exr|hdr|tif|tiff|jpg|jpeg|ppm)' -- "$cur")) ;;
        *) COMPREPLY=($(compgen -f -X "!*.@(${scenes:-wrl}|gz|png|exr|hdr|tif|ppm|jpg)" -- "$cur")) ;;
    esac
    compopt -o plusdirs 2>/dev/null
}
complete -F _vrmlray vrmlray
