// The sweep kinds of the scene files read without Python. The specification is
// python/hovering/scenes/schema.py (parse_scene(..., check_output=False) after load_scene's file
// checks): the same keys, defaults, ranges, order of the checks and message texts, so that a scene
// fails in the same words whichever program reads it. tests/test_scene_cpp.py holds the two to it.
//
// Python's messages quote values with repr(), so this file reproduces repr() of what tomllib
// would have returned, Python's float repr and '.6g' formatting, the restricted expression
// language of _real (CPython's tokenizer and float semantics), matplotlib's is_color_like and the
// checks of the objects Python builds to validate (TruncatedMap, StepSystem), which are the core's.
#include "hovering/scene/sweep_scene.hpp"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <tuple>
#include <utility>
#include <vector>

#include <toml++/toml.h>

#include "hovering/flow/potential.hpp"
#include "hovering/flow/system.hpp"
#include "hovering/truncated/map.hpp"

namespace hovering::scene {

namespace {

struct IdentRange {
    char32_t first, last;
    char ascii;   // the NFKC form of `first`; the range maps on in step
    bool start;   // may begin an identifier (XID_Start)
};

// ------------------------------------------------------------------------------------------------
// Tables generated from the Python and matplotlib of the project's environment (the generator:
// sorted(matplotlib.colors._colors_full_map); ranges of `not chr(c).isprintable()`; `chr(c).isspace()`;
// the zeros of unicodedata category Nd; identifier characters with a one-character ASCII NFKC form).

// Every name matplotlib 3.11.2 accepts (matplotlib.colors._colors_full_map: CSS4, base, Tableau
// 'tab:', xkcd 'xkcd:' and their 'grey' spellings), sorted for binary search.
constexpr std::array<std::string_view, 1163> kColourNames{
    "aliceblue", "antiquewhite", "aqua", "aquamarine", "azure", "b", "beige", "bisque", "black", "blanchedalmond",
    "blue", "blueviolet", "brown", "burlywood", "c", "cadetblue", "chartreuse", "chocolate", "coral",
    "cornflowerblue", "cornsilk", "crimson", "cyan", "darkblue", "darkcyan", "darkgoldenrod", "darkgray", "darkgreen",
    "darkgrey", "darkkhaki", "darkmagenta", "darkolivegreen", "darkorange", "darkorchid", "darkred", "darksalmon",
    "darkseagreen", "darkslateblue", "darkslategray", "darkslategrey", "darkturquoise", "darkviolet", "deeppink",
    "deepskyblue", "dimgray", "dimgrey", "dodgerblue", "firebrick", "floralwhite", "forestgreen", "fuchsia", "g",
    "gainsboro", "ghostwhite", "gold", "goldenrod", "gray", "green", "greenyellow", "grey", "honeydew", "hotpink",
    "indianred", "indigo", "ivory", "k", "khaki", "lavender", "lavenderblush", "lawngreen", "lemonchiffon",
    "lightblue", "lightcoral", "lightcyan", "lightgoldenrodyellow", "lightgray", "lightgreen", "lightgrey",
    "lightpink", "lightsalmon", "lightseagreen", "lightskyblue", "lightslategray", "lightslategrey", "lightsteelblue",
    "lightyellow", "lime", "limegreen", "linen", "m", "magenta", "maroon", "mediumaquamarine", "mediumblue",
    "mediumorchid", "mediumpurple", "mediumseagreen", "mediumslateblue", "mediumspringgreen", "mediumturquoise",
    "mediumvioletred", "midnightblue", "mintcream", "mistyrose", "moccasin", "navajowhite", "navy", "oldlace",
    "olive", "olivedrab", "orange", "orangered", "orchid", "palegoldenrod", "palegreen", "paleturquoise",
    "palevioletred", "papayawhip", "peachpuff", "peru", "pink", "plum", "powderblue", "purple", "r", "rebeccapurple",
    "red", "rosybrown", "royalblue", "saddlebrown", "salmon", "sandybrown", "seagreen", "seashell", "sienna",
    "silver", "skyblue", "slateblue", "slategray", "slategrey", "snow", "springgreen", "steelblue", "tab:blue",
    "tab:brown", "tab:cyan", "tab:gray", "tab:green", "tab:grey", "tab:olive", "tab:orange", "tab:pink", "tab:purple",
    "tab:red", "tan", "teal", "thistle", "tomato", "turquoise", "violet", "w", "wheat", "white", "whitesmoke",
    "xkcd:acid green", "xkcd:adobe", "xkcd:algae", "xkcd:algae green", "xkcd:almost black", "xkcd:amber",
    "xkcd:amethyst", "xkcd:apple", "xkcd:apple green", "xkcd:apricot", "xkcd:aqua", "xkcd:aqua blue",
    "xkcd:aqua green", "xkcd:aqua marine", "xkcd:aquamarine", "xkcd:army green", "xkcd:asparagus", "xkcd:aubergine",
    "xkcd:auburn", "xkcd:avocado", "xkcd:avocado green", "xkcd:azul", "xkcd:azure", "xkcd:baby blue",
    "xkcd:baby green", "xkcd:baby pink", "xkcd:baby poo", "xkcd:baby poop", "xkcd:baby poop green",
    "xkcd:baby puke green", "xkcd:baby purple", "xkcd:baby shit brown", "xkcd:baby shit green", "xkcd:banana",
    "xkcd:banana yellow", "xkcd:barbie pink", "xkcd:barf green", "xkcd:barney", "xkcd:barney purple",
    "xkcd:battleship gray", "xkcd:battleship grey", "xkcd:beige", "xkcd:berry", "xkcd:bile", "xkcd:black",
    "xkcd:bland", "xkcd:blood", "xkcd:blood orange", "xkcd:blood red", "xkcd:blue", "xkcd:blue blue",
    "xkcd:blue gray", "xkcd:blue green", "xkcd:blue grey", "xkcd:blue purple", "xkcd:blue violet",
    "xkcd:blue with a hint of purple", "xkcd:blue/gray", "xkcd:blue/green", "xkcd:blue/grey", "xkcd:blue/purple",
    "xkcd:blueberry", "xkcd:bluegray", "xkcd:bluegreen", "xkcd:bluegrey", "xkcd:bluey gray", "xkcd:bluey green",
    "xkcd:bluey grey", "xkcd:bluey purple", "xkcd:bluish", "xkcd:bluish gray", "xkcd:bluish green",
    "xkcd:bluish grey", "xkcd:bluish purple", "xkcd:blurple", "xkcd:blush", "xkcd:blush pink", "xkcd:booger",
    "xkcd:booger green", "xkcd:bordeaux", "xkcd:boring green", "xkcd:bottle green", "xkcd:brick", "xkcd:brick orange",
    "xkcd:brick red", "xkcd:bright aqua", "xkcd:bright blue", "xkcd:bright cyan", "xkcd:bright green",
    "xkcd:bright lavender", "xkcd:bright light blue", "xkcd:bright light green", "xkcd:bright lilac",
    "xkcd:bright lime", "xkcd:bright lime green", "xkcd:bright magenta", "xkcd:bright olive", "xkcd:bright orange",
    "xkcd:bright pink", "xkcd:bright purple", "xkcd:bright red", "xkcd:bright sea green", "xkcd:bright sky blue",
    "xkcd:bright teal", "xkcd:bright turquoise", "xkcd:bright violet", "xkcd:bright yellow",
    "xkcd:bright yellow green", "xkcd:british racing green", "xkcd:bronze", "xkcd:brown", "xkcd:brown gray",
    "xkcd:brown green", "xkcd:brown grey", "xkcd:brown orange", "xkcd:brown red", "xkcd:brown yellow",
    "xkcd:brownish", "xkcd:brownish gray", "xkcd:brownish green", "xkcd:brownish grey", "xkcd:brownish orange",
    "xkcd:brownish pink", "xkcd:brownish purple", "xkcd:brownish red", "xkcd:brownish yellow", "xkcd:browny green",
    "xkcd:browny orange", "xkcd:bruise", "xkcd:bubble gum pink", "xkcd:bubblegum", "xkcd:bubblegum pink", "xkcd:buff",
    "xkcd:burgundy", "xkcd:burnt orange", "xkcd:burnt red", "xkcd:burnt siena", "xkcd:burnt sienna",
    "xkcd:burnt umber", "xkcd:burnt yellow", "xkcd:burple", "xkcd:butter", "xkcd:butter yellow", "xkcd:butterscotch",
    "xkcd:cadet blue", "xkcd:camel", "xkcd:camo", "xkcd:camo green", "xkcd:camouflage green", "xkcd:canary",
    "xkcd:canary yellow", "xkcd:candy pink", "xkcd:caramel", "xkcd:carmine", "xkcd:carnation", "xkcd:carnation pink",
    "xkcd:carolina blue", "xkcd:celadon", "xkcd:celery", "xkcd:cement", "xkcd:cerise", "xkcd:cerulean",
    "xkcd:cerulean blue", "xkcd:charcoal", "xkcd:charcoal gray", "xkcd:charcoal grey", "xkcd:chartreuse",
    "xkcd:cherry", "xkcd:cherry red", "xkcd:chestnut", "xkcd:chocolate", "xkcd:chocolate brown", "xkcd:cinnamon",
    "xkcd:claret", "xkcd:clay", "xkcd:clay brown", "xkcd:clear blue", "xkcd:cloudy blue", "xkcd:cobalt",
    "xkcd:cobalt blue", "xkcd:cocoa", "xkcd:coffee", "xkcd:cool blue", "xkcd:cool gray", "xkcd:cool green",
    "xkcd:cool grey", "xkcd:copper", "xkcd:coral", "xkcd:coral pink", "xkcd:cornflower", "xkcd:cornflower blue",
    "xkcd:cranberry", "xkcd:cream", "xkcd:creme", "xkcd:crimson", "xkcd:custard", "xkcd:cyan", "xkcd:dandelion",
    "xkcd:dark", "xkcd:dark aqua", "xkcd:dark aquamarine", "xkcd:dark beige", "xkcd:dark blue", "xkcd:dark blue gray",
    "xkcd:dark blue green", "xkcd:dark blue grey", "xkcd:dark brown", "xkcd:dark coral", "xkcd:dark cream",
    "xkcd:dark cyan", "xkcd:dark forest green", "xkcd:dark fuchsia", "xkcd:dark gold", "xkcd:dark grass green",
    "xkcd:dark gray", "xkcd:dark gray blue", "xkcd:dark green", "xkcd:dark green blue", "xkcd:dark grey",
    "xkcd:dark grey blue", "xkcd:dark hot pink", "xkcd:dark indigo", "xkcd:dark khaki", "xkcd:dark lavender",
    "xkcd:dark lilac", "xkcd:dark lime", "xkcd:dark lime green", "xkcd:dark magenta", "xkcd:dark maroon",
    "xkcd:dark mauve", "xkcd:dark mint", "xkcd:dark mint green", "xkcd:dark mustard", "xkcd:dark navy",
    "xkcd:dark navy blue", "xkcd:dark olive", "xkcd:dark olive green", "xkcd:dark orange", "xkcd:dark pastel green",
    "xkcd:dark peach", "xkcd:dark periwinkle", "xkcd:dark pink", "xkcd:dark plum", "xkcd:dark purple",
    "xkcd:dark red", "xkcd:dark rose", "xkcd:dark royal blue", "xkcd:dark sage", "xkcd:dark salmon", "xkcd:dark sand",
    "xkcd:dark sea green", "xkcd:dark seafoam", "xkcd:dark seafoam green", "xkcd:dark sky blue",
    "xkcd:dark slate blue", "xkcd:dark tan", "xkcd:dark taupe", "xkcd:dark teal", "xkcd:dark turquoise",
    "xkcd:dark violet", "xkcd:dark yellow", "xkcd:dark yellow green", "xkcd:darkblue", "xkcd:darkgreen",
    "xkcd:darkish blue", "xkcd:darkish green", "xkcd:darkish pink", "xkcd:darkish purple", "xkcd:darkish red",
    "xkcd:deep aqua", "xkcd:deep blue", "xkcd:deep brown", "xkcd:deep green", "xkcd:deep lavender", "xkcd:deep lilac",
    "xkcd:deep magenta", "xkcd:deep orange", "xkcd:deep pink", "xkcd:deep purple", "xkcd:deep red", "xkcd:deep rose",
    "xkcd:deep sea blue", "xkcd:deep sky blue", "xkcd:deep teal", "xkcd:deep turquoise", "xkcd:deep violet",
    "xkcd:denim", "xkcd:denim blue", "xkcd:desert", "xkcd:diarrhea", "xkcd:dirt", "xkcd:dirt brown",
    "xkcd:dirty blue", "xkcd:dirty green", "xkcd:dirty orange", "xkcd:dirty pink", "xkcd:dirty purple",
    "xkcd:dirty yellow", "xkcd:dodger blue", "xkcd:drab", "xkcd:drab green", "xkcd:dried blood", "xkcd:duck egg blue",
    "xkcd:dull blue", "xkcd:dull brown", "xkcd:dull green", "xkcd:dull orange", "xkcd:dull pink", "xkcd:dull purple",
    "xkcd:dull red", "xkcd:dull teal", "xkcd:dull yellow", "xkcd:dusk", "xkcd:dusk blue", "xkcd:dusky blue",
    "xkcd:dusky pink", "xkcd:dusky purple", "xkcd:dusky rose", "xkcd:dust", "xkcd:dusty blue", "xkcd:dusty green",
    "xkcd:dusty lavender", "xkcd:dusty orange", "xkcd:dusty pink", "xkcd:dusty purple", "xkcd:dusty red",
    "xkcd:dusty rose", "xkcd:dusty teal", "xkcd:earth", "xkcd:easter green", "xkcd:easter purple", "xkcd:ecru",
    "xkcd:egg shell", "xkcd:eggplant", "xkcd:eggplant purple", "xkcd:eggshell", "xkcd:eggshell blue",
    "xkcd:electric blue", "xkcd:electric green", "xkcd:electric lime", "xkcd:electric pink", "xkcd:electric purple",
    "xkcd:emerald", "xkcd:emerald green", "xkcd:evergreen", "xkcd:faded blue", "xkcd:faded green",
    "xkcd:faded orange", "xkcd:faded pink", "xkcd:faded purple", "xkcd:faded red", "xkcd:faded yellow", "xkcd:fawn",
    "xkcd:fern", "xkcd:fern green", "xkcd:fire engine red", "xkcd:flat blue", "xkcd:flat green",
    "xkcd:fluorescent green", "xkcd:fluro green", "xkcd:foam green", "xkcd:forest", "xkcd:forest green",
    "xkcd:forrest green", "xkcd:french blue", "xkcd:fresh green", "xkcd:frog green", "xkcd:fuchsia", "xkcd:gold",
    "xkcd:golden", "xkcd:golden brown", "xkcd:golden rod", "xkcd:golden yellow", "xkcd:goldenrod", "xkcd:grape",
    "xkcd:grape purple", "xkcd:grapefruit", "xkcd:grass", "xkcd:grass green", "xkcd:grassy green", "xkcd:gray",
    "xkcd:gray blue", "xkcd:gray brown", "xkcd:gray green", "xkcd:gray pink", "xkcd:gray purple", "xkcd:gray teal",
    "xkcd:gray/blue", "xkcd:gray/green", "xkcd:grayblue", "xkcd:grayish", "xkcd:grayish blue", "xkcd:grayish brown",
    "xkcd:grayish green", "xkcd:grayish pink", "xkcd:grayish purple", "xkcd:grayish teal", "xkcd:green",
    "xkcd:green apple", "xkcd:green blue", "xkcd:green brown", "xkcd:green gray", "xkcd:green grey",
    "xkcd:green teal", "xkcd:green yellow", "xkcd:green/blue", "xkcd:green/yellow", "xkcd:greenblue", "xkcd:greenish",
    "xkcd:greenish beige", "xkcd:greenish blue", "xkcd:greenish brown", "xkcd:greenish cyan", "xkcd:greenish gray",
    "xkcd:greenish grey", "xkcd:greenish tan", "xkcd:greenish teal", "xkcd:greenish turquoise",
    "xkcd:greenish yellow", "xkcd:greeny blue", "xkcd:greeny brown", "xkcd:greeny gray", "xkcd:greeny grey",
    "xkcd:greeny yellow", "xkcd:grey", "xkcd:grey blue", "xkcd:grey brown", "xkcd:grey green", "xkcd:grey pink",
    "xkcd:grey purple", "xkcd:grey teal", "xkcd:grey/blue", "xkcd:grey/green", "xkcd:greyblue", "xkcd:greyish",
    "xkcd:greyish blue", "xkcd:greyish brown", "xkcd:greyish green", "xkcd:greyish pink", "xkcd:greyish purple",
    "xkcd:greyish teal", "xkcd:gross green", "xkcd:gunmetal", "xkcd:hazel", "xkcd:heather", "xkcd:heliotrope",
    "xkcd:highlighter green", "xkcd:hospital green", "xkcd:hot green", "xkcd:hot magenta", "xkcd:hot pink",
    "xkcd:hot purple", "xkcd:hunter green", "xkcd:ice", "xkcd:ice blue", "xkcd:icky green", "xkcd:indian red",
    "xkcd:indigo", "xkcd:indigo blue", "xkcd:iris", "xkcd:irish green", "xkcd:ivory", "xkcd:jade", "xkcd:jade green",
    "xkcd:jungle green", "xkcd:kelley green", "xkcd:kelly green", "xkcd:kermit green", "xkcd:key lime", "xkcd:khaki",
    "xkcd:khaki green", "xkcd:kiwi", "xkcd:kiwi green", "xkcd:lavender", "xkcd:lavender blue", "xkcd:lavender pink",
    "xkcd:lawn green", "xkcd:leaf", "xkcd:leaf green", "xkcd:leafy green", "xkcd:leather", "xkcd:lemon",
    "xkcd:lemon green", "xkcd:lemon lime", "xkcd:lemon yellow", "xkcd:lichen", "xkcd:light aqua",
    "xkcd:light aquamarine", "xkcd:light beige", "xkcd:light blue", "xkcd:light blue gray", "xkcd:light blue green",
    "xkcd:light blue grey", "xkcd:light bluish green", "xkcd:light bright green", "xkcd:light brown",
    "xkcd:light burgundy", "xkcd:light cyan", "xkcd:light eggplant", "xkcd:light forest green", "xkcd:light gold",
    "xkcd:light grass green", "xkcd:light gray", "xkcd:light gray blue", "xkcd:light gray green", "xkcd:light green",
    "xkcd:light green blue", "xkcd:light greenish blue", "xkcd:light grey", "xkcd:light grey blue",
    "xkcd:light grey green", "xkcd:light indigo", "xkcd:light khaki", "xkcd:light lavendar", "xkcd:light lavender",
    "xkcd:light light blue", "xkcd:light light green", "xkcd:light lilac", "xkcd:light lime", "xkcd:light lime green",
    "xkcd:light magenta", "xkcd:light maroon", "xkcd:light mauve", "xkcd:light mint", "xkcd:light mint green",
    "xkcd:light moss green", "xkcd:light mustard", "xkcd:light navy", "xkcd:light navy blue", "xkcd:light neon green",
    "xkcd:light olive", "xkcd:light olive green", "xkcd:light orange", "xkcd:light pastel green",
    "xkcd:light pea green", "xkcd:light peach", "xkcd:light periwinkle", "xkcd:light pink", "xkcd:light plum",
    "xkcd:light purple", "xkcd:light red", "xkcd:light rose", "xkcd:light royal blue", "xkcd:light sage",
    "xkcd:light salmon", "xkcd:light sea green", "xkcd:light seafoam", "xkcd:light seafoam green",
    "xkcd:light sky blue", "xkcd:light tan", "xkcd:light teal", "xkcd:light turquoise", "xkcd:light urple",
    "xkcd:light violet", "xkcd:light yellow", "xkcd:light yellow green", "xkcd:light yellowish green",
    "xkcd:lightblue", "xkcd:lighter green", "xkcd:lighter purple", "xkcd:lightgreen", "xkcd:lightish blue",
    "xkcd:lightish green", "xkcd:lightish purple", "xkcd:lightish red", "xkcd:lilac", "xkcd:liliac", "xkcd:lime",
    "xkcd:lime green", "xkcd:lime yellow", "xkcd:lipstick", "xkcd:lipstick red", "xkcd:macaroni and cheese",
    "xkcd:magenta", "xkcd:mahogany", "xkcd:maize", "xkcd:mango", "xkcd:manilla", "xkcd:marigold", "xkcd:marine",
    "xkcd:marine blue", "xkcd:maroon", "xkcd:mauve", "xkcd:medium blue", "xkcd:medium brown", "xkcd:medium gray",
    "xkcd:medium green", "xkcd:medium grey", "xkcd:medium pink", "xkcd:medium purple", "xkcd:melon", "xkcd:merlot",
    "xkcd:metallic blue", "xkcd:mid blue", "xkcd:mid green", "xkcd:midnight", "xkcd:midnight blue",
    "xkcd:midnight purple", "xkcd:military green", "xkcd:milk chocolate", "xkcd:mint", "xkcd:mint green",
    "xkcd:minty green", "xkcd:mocha", "xkcd:moss", "xkcd:moss green", "xkcd:mossy green", "xkcd:mud",
    "xkcd:mud brown", "xkcd:mud green", "xkcd:muddy brown", "xkcd:muddy green", "xkcd:muddy yellow", "xkcd:mulberry",
    "xkcd:murky green", "xkcd:mushroom", "xkcd:mustard", "xkcd:mustard brown", "xkcd:mustard green",
    "xkcd:mustard yellow", "xkcd:muted blue", "xkcd:muted green", "xkcd:muted pink", "xkcd:muted purple",
    "xkcd:nasty green", "xkcd:navy", "xkcd:navy blue", "xkcd:navy green", "xkcd:neon blue", "xkcd:neon green",
    "xkcd:neon pink", "xkcd:neon purple", "xkcd:neon red", "xkcd:neon yellow", "xkcd:nice blue", "xkcd:night blue",
    "xkcd:ocean", "xkcd:ocean blue", "xkcd:ocean green", "xkcd:ocher", "xkcd:ochre", "xkcd:ocre", "xkcd:off blue",
    "xkcd:off green", "xkcd:off white", "xkcd:off yellow", "xkcd:old pink", "xkcd:old rose", "xkcd:olive",
    "xkcd:olive brown", "xkcd:olive drab", "xkcd:olive green", "xkcd:olive yellow", "xkcd:orange",
    "xkcd:orange brown", "xkcd:orange pink", "xkcd:orange red", "xkcd:orange yellow", "xkcd:orangeish",
    "xkcd:orangered", "xkcd:orangey brown", "xkcd:orangey red", "xkcd:orangey yellow", "xkcd:orangish",
    "xkcd:orangish brown", "xkcd:orangish red", "xkcd:orchid", "xkcd:pale", "xkcd:pale aqua", "xkcd:pale blue",
    "xkcd:pale brown", "xkcd:pale cyan", "xkcd:pale gold", "xkcd:pale gray", "xkcd:pale green", "xkcd:pale grey",
    "xkcd:pale lavender", "xkcd:pale light green", "xkcd:pale lilac", "xkcd:pale lime", "xkcd:pale lime green",
    "xkcd:pale magenta", "xkcd:pale mauve", "xkcd:pale olive", "xkcd:pale olive green", "xkcd:pale orange",
    "xkcd:pale peach", "xkcd:pale pink", "xkcd:pale purple", "xkcd:pale red", "xkcd:pale rose", "xkcd:pale salmon",
    "xkcd:pale sky blue", "xkcd:pale teal", "xkcd:pale turquoise", "xkcd:pale violet", "xkcd:pale yellow",
    "xkcd:parchment", "xkcd:pastel blue", "xkcd:pastel green", "xkcd:pastel orange", "xkcd:pastel pink",
    "xkcd:pastel purple", "xkcd:pastel red", "xkcd:pastel yellow", "xkcd:pea", "xkcd:pea green", "xkcd:pea soup",
    "xkcd:pea soup green", "xkcd:peach", "xkcd:peachy pink", "xkcd:peacock blue", "xkcd:pear", "xkcd:periwinkle",
    "xkcd:periwinkle blue", "xkcd:perrywinkle", "xkcd:petrol", "xkcd:pig pink", "xkcd:pine", "xkcd:pine green",
    "xkcd:pink", "xkcd:pink purple", "xkcd:pink red", "xkcd:pink/purple", "xkcd:pinkish", "xkcd:pinkish brown",
    "xkcd:pinkish gray", "xkcd:pinkish grey", "xkcd:pinkish orange", "xkcd:pinkish purple", "xkcd:pinkish red",
    "xkcd:pinkish tan", "xkcd:pinky", "xkcd:pinky purple", "xkcd:pinky red", "xkcd:piss yellow", "xkcd:pistachio",
    "xkcd:plum", "xkcd:plum purple", "xkcd:poison green", "xkcd:poo", "xkcd:poo brown", "xkcd:poop",
    "xkcd:poop brown", "xkcd:poop green", "xkcd:powder blue", "xkcd:powder pink", "xkcd:primary blue",
    "xkcd:prussian blue", "xkcd:puce", "xkcd:puke", "xkcd:puke brown", "xkcd:puke green", "xkcd:puke yellow",
    "xkcd:pumpkin", "xkcd:pumpkin orange", "xkcd:pure blue", "xkcd:purple", "xkcd:purple blue", "xkcd:purple brown",
    "xkcd:purple gray", "xkcd:purple grey", "xkcd:purple pink", "xkcd:purple red", "xkcd:purple/blue",
    "xkcd:purple/pink", "xkcd:purpleish", "xkcd:purpleish blue", "xkcd:purpleish pink", "xkcd:purpley",
    "xkcd:purpley blue", "xkcd:purpley gray", "xkcd:purpley grey", "xkcd:purpley pink", "xkcd:purplish",
    "xkcd:purplish blue", "xkcd:purplish brown", "xkcd:purplish gray", "xkcd:purplish grey", "xkcd:purplish pink",
    "xkcd:purplish red", "xkcd:purply", "xkcd:purply blue", "xkcd:purply pink", "xkcd:putty", "xkcd:racing green",
    "xkcd:radioactive green", "xkcd:raspberry", "xkcd:raw sienna", "xkcd:raw umber", "xkcd:really light blue",
    "xkcd:red", "xkcd:red brown", "xkcd:red orange", "xkcd:red pink", "xkcd:red purple", "xkcd:red violet",
    "xkcd:red wine", "xkcd:reddish", "xkcd:reddish brown", "xkcd:reddish gray", "xkcd:reddish grey",
    "xkcd:reddish orange", "xkcd:reddish pink", "xkcd:reddish purple", "xkcd:reddy brown", "xkcd:rich blue",
    "xkcd:rich purple", "xkcd:robin egg blue", "xkcd:robin's egg", "xkcd:robin's egg blue", "xkcd:rosa", "xkcd:rose",
    "xkcd:rose pink", "xkcd:rose red", "xkcd:rosy pink", "xkcd:rouge", "xkcd:royal", "xkcd:royal blue",
    "xkcd:royal purple", "xkcd:ruby", "xkcd:russet", "xkcd:rust", "xkcd:rust brown", "xkcd:rust orange",
    "xkcd:rust red", "xkcd:rusty orange", "xkcd:rusty red", "xkcd:saffron", "xkcd:sage", "xkcd:sage green",
    "xkcd:salmon", "xkcd:salmon pink", "xkcd:sand", "xkcd:sand brown", "xkcd:sand yellow", "xkcd:sandstone",
    "xkcd:sandy", "xkcd:sandy brown", "xkcd:sandy yellow", "xkcd:sap green", "xkcd:sapphire", "xkcd:scarlet",
    "xkcd:sea", "xkcd:sea blue", "xkcd:sea green", "xkcd:seafoam", "xkcd:seafoam blue", "xkcd:seafoam green",
    "xkcd:seaweed", "xkcd:seaweed green", "xkcd:sepia", "xkcd:shamrock", "xkcd:shamrock green", "xkcd:shit",
    "xkcd:shit brown", "xkcd:shit green", "xkcd:shocking pink", "xkcd:sick green", "xkcd:sickly green",
    "xkcd:sickly yellow", "xkcd:sienna", "xkcd:silver", "xkcd:sky", "xkcd:sky blue", "xkcd:slate", "xkcd:slate blue",
    "xkcd:slate gray", "xkcd:slate green", "xkcd:slate grey", "xkcd:slime green", "xkcd:snot", "xkcd:snot green",
    "xkcd:soft blue", "xkcd:soft green", "xkcd:soft pink", "xkcd:soft purple", "xkcd:spearmint", "xkcd:spring green",
    "xkcd:spruce", "xkcd:squash", "xkcd:steel", "xkcd:steel blue", "xkcd:steel gray", "xkcd:steel grey", "xkcd:stone",
    "xkcd:stormy blue", "xkcd:straw", "xkcd:strawberry", "xkcd:strong blue", "xkcd:strong pink", "xkcd:sun yellow",
    "xkcd:sunflower", "xkcd:sunflower yellow", "xkcd:sunny yellow", "xkcd:sunshine yellow", "xkcd:swamp",
    "xkcd:swamp green", "xkcd:tan", "xkcd:tan brown", "xkcd:tan green", "xkcd:tangerine", "xkcd:taupe", "xkcd:tea",
    "xkcd:tea green", "xkcd:teal", "xkcd:teal blue", "xkcd:teal green", "xkcd:tealish", "xkcd:tealish green",
    "xkcd:terra cotta", "xkcd:terracota", "xkcd:terracotta", "xkcd:tiffany blue", "xkcd:tomato", "xkcd:tomato red",
    "xkcd:topaz", "xkcd:toupe", "xkcd:toxic green", "xkcd:tree green", "xkcd:true blue", "xkcd:true green",
    "xkcd:turquoise", "xkcd:turquoise blue", "xkcd:turquoise green", "xkcd:turtle green", "xkcd:twilight",
    "xkcd:twilight blue", "xkcd:ugly blue", "xkcd:ugly brown", "xkcd:ugly green", "xkcd:ugly pink",
    "xkcd:ugly purple", "xkcd:ugly yellow", "xkcd:ultramarine", "xkcd:ultramarine blue", "xkcd:umber", "xkcd:velvet",
    "xkcd:vermillion", "xkcd:very dark blue", "xkcd:very dark brown", "xkcd:very dark green", "xkcd:very dark purple",
    "xkcd:very light blue", "xkcd:very light brown", "xkcd:very light green", "xkcd:very light pink",
    "xkcd:very light purple", "xkcd:very pale blue", "xkcd:very pale green", "xkcd:vibrant blue",
    "xkcd:vibrant green", "xkcd:vibrant purple", "xkcd:violet", "xkcd:violet blue", "xkcd:violet pink",
    "xkcd:violet red", "xkcd:viridian", "xkcd:vivid blue", "xkcd:vivid green", "xkcd:vivid purple", "xkcd:vomit",
    "xkcd:vomit green", "xkcd:vomit yellow", "xkcd:warm blue", "xkcd:warm brown", "xkcd:warm gray", "xkcd:warm grey",
    "xkcd:warm pink", "xkcd:warm purple", "xkcd:washed out green", "xkcd:water blue", "xkcd:watermelon",
    "xkcd:weird green", "xkcd:wheat", "xkcd:white", "xkcd:windows blue", "xkcd:wine", "xkcd:wine red",
    "xkcd:wintergreen", "xkcd:wisteria", "xkcd:yellow", "xkcd:yellow brown", "xkcd:yellow green", "xkcd:yellow ochre",
    "xkcd:yellow orange", "xkcd:yellow tan", "xkcd:yellow/green", "xkcd:yellowgreen", "xkcd:yellowish",
    "xkcd:yellowish brown", "xkcd:yellowish green", "xkcd:yellowish orange", "xkcd:yellowish tan",
    "xkcd:yellowy brown", "xkcd:yellowy green", "y", "yellow", "yellowgreen",
};

// Code points str.isprintable() rejects (Python 3.11.7, Unicode 14.0.0), as closed ranges:
// repr() escapes them.
constexpr std::array<std::pair<char32_t, char32_t>, 701> kNonPrintable{{
    {0x0, 0x1f}, {0x7f, 0xa0}, {0xad, 0xad}, {0x378, 0x379}, {0x380, 0x383}, {0x38b, 0x38b}, {0x38d, 0x38d},
    {0x3a2, 0x3a2}, {0x530, 0x530}, {0x557, 0x558}, {0x58b, 0x58c}, {0x590, 0x590}, {0x5c8, 0x5cf}, {0x5eb, 0x5ee},
    {0x5f5, 0x605}, {0x61c, 0x61c}, {0x6dd, 0x6dd}, {0x70e, 0x70f}, {0x74b, 0x74c}, {0x7b2, 0x7bf}, {0x7fb, 0x7fc},
    {0x82e, 0x82f}, {0x83f, 0x83f}, {0x85c, 0x85d}, {0x85f, 0x85f}, {0x86b, 0x86f}, {0x88f, 0x897}, {0x8e2, 0x8e2},
    {0x984, 0x984}, {0x98d, 0x98e}, {0x991, 0x992}, {0x9a9, 0x9a9}, {0x9b1, 0x9b1}, {0x9b3, 0x9b5}, {0x9ba, 0x9bb},
    {0x9c5, 0x9c6}, {0x9c9, 0x9ca}, {0x9cf, 0x9d6}, {0x9d8, 0x9db}, {0x9de, 0x9de}, {0x9e4, 0x9e5}, {0x9ff, 0xa00},
    {0xa04, 0xa04}, {0xa0b, 0xa0e}, {0xa11, 0xa12}, {0xa29, 0xa29}, {0xa31, 0xa31}, {0xa34, 0xa34}, {0xa37, 0xa37},
    {0xa3a, 0xa3b}, {0xa3d, 0xa3d}, {0xa43, 0xa46}, {0xa49, 0xa4a}, {0xa4e, 0xa50}, {0xa52, 0xa58}, {0xa5d, 0xa5d},
    {0xa5f, 0xa65}, {0xa77, 0xa80}, {0xa84, 0xa84}, {0xa8e, 0xa8e}, {0xa92, 0xa92}, {0xaa9, 0xaa9}, {0xab1, 0xab1},
    {0xab4, 0xab4}, {0xaba, 0xabb}, {0xac6, 0xac6}, {0xaca, 0xaca}, {0xace, 0xacf}, {0xad1, 0xadf}, {0xae4, 0xae5},
    {0xaf2, 0xaf8}, {0xb00, 0xb00}, {0xb04, 0xb04}, {0xb0d, 0xb0e}, {0xb11, 0xb12}, {0xb29, 0xb29}, {0xb31, 0xb31},
    {0xb34, 0xb34}, {0xb3a, 0xb3b}, {0xb45, 0xb46}, {0xb49, 0xb4a}, {0xb4e, 0xb54}, {0xb58, 0xb5b}, {0xb5e, 0xb5e},
    {0xb64, 0xb65}, {0xb78, 0xb81}, {0xb84, 0xb84}, {0xb8b, 0xb8d}, {0xb91, 0xb91}, {0xb96, 0xb98}, {0xb9b, 0xb9b},
    {0xb9d, 0xb9d}, {0xba0, 0xba2}, {0xba5, 0xba7}, {0xbab, 0xbad}, {0xbba, 0xbbd}, {0xbc3, 0xbc5}, {0xbc9, 0xbc9},
    {0xbce, 0xbcf}, {0xbd1, 0xbd6}, {0xbd8, 0xbe5}, {0xbfb, 0xbff}, {0xc0d, 0xc0d}, {0xc11, 0xc11}, {0xc29, 0xc29},
    {0xc3a, 0xc3b}, {0xc45, 0xc45}, {0xc49, 0xc49}, {0xc4e, 0xc54}, {0xc57, 0xc57}, {0xc5b, 0xc5c}, {0xc5e, 0xc5f},
    {0xc64, 0xc65}, {0xc70, 0xc76}, {0xc8d, 0xc8d}, {0xc91, 0xc91}, {0xca9, 0xca9}, {0xcb4, 0xcb4}, {0xcba, 0xcbb},
    {0xcc5, 0xcc5}, {0xcc9, 0xcc9}, {0xcce, 0xcd4}, {0xcd7, 0xcdc}, {0xcdf, 0xcdf}, {0xce4, 0xce5}, {0xcf0, 0xcf0},
    {0xcf3, 0xcff}, {0xd0d, 0xd0d}, {0xd11, 0xd11}, {0xd45, 0xd45}, {0xd49, 0xd49}, {0xd50, 0xd53}, {0xd64, 0xd65},
    {0xd80, 0xd80}, {0xd84, 0xd84}, {0xd97, 0xd99}, {0xdb2, 0xdb2}, {0xdbc, 0xdbc}, {0xdbe, 0xdbf}, {0xdc7, 0xdc9},
    {0xdcb, 0xdce}, {0xdd5, 0xdd5}, {0xdd7, 0xdd7}, {0xde0, 0xde5}, {0xdf0, 0xdf1}, {0xdf5, 0xe00}, {0xe3b, 0xe3e},
    {0xe5c, 0xe80}, {0xe83, 0xe83}, {0xe85, 0xe85}, {0xe8b, 0xe8b}, {0xea4, 0xea4}, {0xea6, 0xea6}, {0xebe, 0xebf},
    {0xec5, 0xec5}, {0xec7, 0xec7}, {0xece, 0xecf}, {0xeda, 0xedb}, {0xee0, 0xeff}, {0xf48, 0xf48}, {0xf6d, 0xf70},
    {0xf98, 0xf98}, {0xfbd, 0xfbd}, {0xfcd, 0xfcd}, {0xfdb, 0xfff}, {0x10c6, 0x10c6}, {0x10c8, 0x10cc},
    {0x10ce, 0x10cf}, {0x1249, 0x1249}, {0x124e, 0x124f}, {0x1257, 0x1257}, {0x1259, 0x1259}, {0x125e, 0x125f},
    {0x1289, 0x1289}, {0x128e, 0x128f}, {0x12b1, 0x12b1}, {0x12b6, 0x12b7}, {0x12bf, 0x12bf}, {0x12c1, 0x12c1},
    {0x12c6, 0x12c7}, {0x12d7, 0x12d7}, {0x1311, 0x1311}, {0x1316, 0x1317}, {0x135b, 0x135c}, {0x137d, 0x137f},
    {0x139a, 0x139f}, {0x13f6, 0x13f7}, {0x13fe, 0x13ff}, {0x1680, 0x1680}, {0x169d, 0x169f}, {0x16f9, 0x16ff},
    {0x1716, 0x171e}, {0x1737, 0x173f}, {0x1754, 0x175f}, {0x176d, 0x176d}, {0x1771, 0x1771}, {0x1774, 0x177f},
    {0x17de, 0x17df}, {0x17ea, 0x17ef}, {0x17fa, 0x17ff}, {0x180e, 0x180e}, {0x181a, 0x181f}, {0x1879, 0x187f},
    {0x18ab, 0x18af}, {0x18f6, 0x18ff}, {0x191f, 0x191f}, {0x192c, 0x192f}, {0x193c, 0x193f}, {0x1941, 0x1943},
    {0x196e, 0x196f}, {0x1975, 0x197f}, {0x19ac, 0x19af}, {0x19ca, 0x19cf}, {0x19db, 0x19dd}, {0x1a1c, 0x1a1d},
    {0x1a5f, 0x1a5f}, {0x1a7d, 0x1a7e}, {0x1a8a, 0x1a8f}, {0x1a9a, 0x1a9f}, {0x1aae, 0x1aaf}, {0x1acf, 0x1aff},
    {0x1b4d, 0x1b4f}, {0x1b7f, 0x1b7f}, {0x1bf4, 0x1bfb}, {0x1c38, 0x1c3a}, {0x1c4a, 0x1c4c}, {0x1c89, 0x1c8f},
    {0x1cbb, 0x1cbc}, {0x1cc8, 0x1ccf}, {0x1cfb, 0x1cff}, {0x1f16, 0x1f17}, {0x1f1e, 0x1f1f}, {0x1f46, 0x1f47},
    {0x1f4e, 0x1f4f}, {0x1f58, 0x1f58}, {0x1f5a, 0x1f5a}, {0x1f5c, 0x1f5c}, {0x1f5e, 0x1f5e}, {0x1f7e, 0x1f7f},
    {0x1fb5, 0x1fb5}, {0x1fc5, 0x1fc5}, {0x1fd4, 0x1fd5}, {0x1fdc, 0x1fdc}, {0x1ff0, 0x1ff1}, {0x1ff5, 0x1ff5},
    {0x1fff, 0x200f}, {0x2028, 0x202f}, {0x205f, 0x206f}, {0x2072, 0x2073}, {0x208f, 0x208f}, {0x209d, 0x209f},
    {0x20c1, 0x20cf}, {0x20f1, 0x20ff}, {0x218c, 0x218f}, {0x2427, 0x243f}, {0x244b, 0x245f}, {0x2b74, 0x2b75},
    {0x2b96, 0x2b96}, {0x2cf4, 0x2cf8}, {0x2d26, 0x2d26}, {0x2d28, 0x2d2c}, {0x2d2e, 0x2d2f}, {0x2d68, 0x2d6e},
    {0x2d71, 0x2d7e}, {0x2d97, 0x2d9f}, {0x2da7, 0x2da7}, {0x2daf, 0x2daf}, {0x2db7, 0x2db7}, {0x2dbf, 0x2dbf},
    {0x2dc7, 0x2dc7}, {0x2dcf, 0x2dcf}, {0x2dd7, 0x2dd7}, {0x2ddf, 0x2ddf}, {0x2e5e, 0x2e7f}, {0x2e9a, 0x2e9a},
    {0x2ef4, 0x2eff}, {0x2fd6, 0x2fef}, {0x2ffc, 0x3000}, {0x3040, 0x3040}, {0x3097, 0x3098}, {0x3100, 0x3104},
    {0x3130, 0x3130}, {0x318f, 0x318f}, {0x31e4, 0x31ef}, {0x321f, 0x321f}, {0xa48d, 0xa48f}, {0xa4c7, 0xa4cf},
    {0xa62c, 0xa63f}, {0xa6f8, 0xa6ff}, {0xa7cb, 0xa7cf}, {0xa7d2, 0xa7d2}, {0xa7d4, 0xa7d4}, {0xa7da, 0xa7f1},
    {0xa82d, 0xa82f}, {0xa83a, 0xa83f}, {0xa878, 0xa87f}, {0xa8c6, 0xa8cd}, {0xa8da, 0xa8df}, {0xa954, 0xa95e},
    {0xa97d, 0xa97f}, {0xa9ce, 0xa9ce}, {0xa9da, 0xa9dd}, {0xa9ff, 0xa9ff}, {0xaa37, 0xaa3f}, {0xaa4e, 0xaa4f},
    {0xaa5a, 0xaa5b}, {0xaac3, 0xaada}, {0xaaf7, 0xab00}, {0xab07, 0xab08}, {0xab0f, 0xab10}, {0xab17, 0xab1f},
    {0xab27, 0xab27}, {0xab2f, 0xab2f}, {0xab6c, 0xab6f}, {0xabee, 0xabef}, {0xabfa, 0xabff}, {0xd7a4, 0xd7af},
    {0xd7c7, 0xd7ca}, {0xd7fc, 0xf8ff}, {0xfa6e, 0xfa6f}, {0xfada, 0xfaff}, {0xfb07, 0xfb12}, {0xfb18, 0xfb1c},
    {0xfb37, 0xfb37}, {0xfb3d, 0xfb3d}, {0xfb3f, 0xfb3f}, {0xfb42, 0xfb42}, {0xfb45, 0xfb45}, {0xfbc3, 0xfbd2},
    {0xfd90, 0xfd91}, {0xfdc8, 0xfdce}, {0xfdd0, 0xfdef}, {0xfe1a, 0xfe1f}, {0xfe53, 0xfe53}, {0xfe67, 0xfe67},
    {0xfe6c, 0xfe6f}, {0xfe75, 0xfe75}, {0xfefd, 0xff00}, {0xffbf, 0xffc1}, {0xffc8, 0xffc9}, {0xffd0, 0xffd1},
    {0xffd8, 0xffd9}, {0xffdd, 0xffdf}, {0xffe7, 0xffe7}, {0xffef, 0xfffb}, {0xfffe, 0xffff}, {0x1000c, 0x1000c},
    {0x10027, 0x10027}, {0x1003b, 0x1003b}, {0x1003e, 0x1003e}, {0x1004e, 0x1004f}, {0x1005e, 0x1007f},
    {0x100fb, 0x100ff}, {0x10103, 0x10106}, {0x10134, 0x10136}, {0x1018f, 0x1018f}, {0x1019d, 0x1019f},
    {0x101a1, 0x101cf}, {0x101fe, 0x1027f}, {0x1029d, 0x1029f}, {0x102d1, 0x102df}, {0x102fc, 0x102ff},
    {0x10324, 0x1032c}, {0x1034b, 0x1034f}, {0x1037b, 0x1037f}, {0x1039e, 0x1039e}, {0x103c4, 0x103c7},
    {0x103d6, 0x103ff}, {0x1049e, 0x1049f}, {0x104aa, 0x104af}, {0x104d4, 0x104d7}, {0x104fc, 0x104ff},
    {0x10528, 0x1052f}, {0x10564, 0x1056e}, {0x1057b, 0x1057b}, {0x1058b, 0x1058b}, {0x10593, 0x10593},
    {0x10596, 0x10596}, {0x105a2, 0x105a2}, {0x105b2, 0x105b2}, {0x105ba, 0x105ba}, {0x105bd, 0x105ff},
    {0x10737, 0x1073f}, {0x10756, 0x1075f}, {0x10768, 0x1077f}, {0x10786, 0x10786}, {0x107b1, 0x107b1},
    {0x107bb, 0x107ff}, {0x10806, 0x10807}, {0x10809, 0x10809}, {0x10836, 0x10836}, {0x10839, 0x1083b},
    {0x1083d, 0x1083e}, {0x10856, 0x10856}, {0x1089f, 0x108a6}, {0x108b0, 0x108df}, {0x108f3, 0x108f3},
    {0x108f6, 0x108fa}, {0x1091c, 0x1091e}, {0x1093a, 0x1093e}, {0x10940, 0x1097f}, {0x109b8, 0x109bb},
    {0x109d0, 0x109d1}, {0x10a04, 0x10a04}, {0x10a07, 0x10a0b}, {0x10a14, 0x10a14}, {0x10a18, 0x10a18},
    {0x10a36, 0x10a37}, {0x10a3b, 0x10a3e}, {0x10a49, 0x10a4f}, {0x10a59, 0x10a5f}, {0x10aa0, 0x10abf},
    {0x10ae7, 0x10aea}, {0x10af7, 0x10aff}, {0x10b36, 0x10b38}, {0x10b56, 0x10b57}, {0x10b73, 0x10b77},
    {0x10b92, 0x10b98}, {0x10b9d, 0x10ba8}, {0x10bb0, 0x10bff}, {0x10c49, 0x10c7f}, {0x10cb3, 0x10cbf},
    {0x10cf3, 0x10cf9}, {0x10d28, 0x10d2f}, {0x10d3a, 0x10e5f}, {0x10e7f, 0x10e7f}, {0x10eaa, 0x10eaa},
    {0x10eae, 0x10eaf}, {0x10eb2, 0x10eff}, {0x10f28, 0x10f2f}, {0x10f5a, 0x10f6f}, {0x10f8a, 0x10faf},
    {0x10fcc, 0x10fdf}, {0x10ff7, 0x10fff}, {0x1104e, 0x11051}, {0x11076, 0x1107e}, {0x110bd, 0x110bd},
    {0x110c3, 0x110cf}, {0x110e9, 0x110ef}, {0x110fa, 0x110ff}, {0x11135, 0x11135}, {0x11148, 0x1114f},
    {0x11177, 0x1117f}, {0x111e0, 0x111e0}, {0x111f5, 0x111ff}, {0x11212, 0x11212}, {0x1123f, 0x1127f},
    {0x11287, 0x11287}, {0x11289, 0x11289}, {0x1128e, 0x1128e}, {0x1129e, 0x1129e}, {0x112aa, 0x112af},
    {0x112eb, 0x112ef}, {0x112fa, 0x112ff}, {0x11304, 0x11304}, {0x1130d, 0x1130e}, {0x11311, 0x11312},
    {0x11329, 0x11329}, {0x11331, 0x11331}, {0x11334, 0x11334}, {0x1133a, 0x1133a}, {0x11345, 0x11346},
    {0x11349, 0x1134a}, {0x1134e, 0x1134f}, {0x11351, 0x11356}, {0x11358, 0x1135c}, {0x11364, 0x11365},
    {0x1136d, 0x1136f}, {0x11375, 0x113ff}, {0x1145c, 0x1145c}, {0x11462, 0x1147f}, {0x114c8, 0x114cf},
    {0x114da, 0x1157f}, {0x115b6, 0x115b7}, {0x115de, 0x115ff}, {0x11645, 0x1164f}, {0x1165a, 0x1165f},
    {0x1166d, 0x1167f}, {0x116ba, 0x116bf}, {0x116ca, 0x116ff}, {0x1171b, 0x1171c}, {0x1172c, 0x1172f},
    {0x11747, 0x117ff}, {0x1183c, 0x1189f}, {0x118f3, 0x118fe}, {0x11907, 0x11908}, {0x1190a, 0x1190b},
    {0x11914, 0x11914}, {0x11917, 0x11917}, {0x11936, 0x11936}, {0x11939, 0x1193a}, {0x11947, 0x1194f},
    {0x1195a, 0x1199f}, {0x119a8, 0x119a9}, {0x119d8, 0x119d9}, {0x119e5, 0x119ff}, {0x11a48, 0x11a4f},
    {0x11aa3, 0x11aaf}, {0x11af9, 0x11bff}, {0x11c09, 0x11c09}, {0x11c37, 0x11c37}, {0x11c46, 0x11c4f},
    {0x11c6d, 0x11c6f}, {0x11c90, 0x11c91}, {0x11ca8, 0x11ca8}, {0x11cb7, 0x11cff}, {0x11d07, 0x11d07},
    {0x11d0a, 0x11d0a}, {0x11d37, 0x11d39}, {0x11d3b, 0x11d3b}, {0x11d3e, 0x11d3e}, {0x11d48, 0x11d4f},
    {0x11d5a, 0x11d5f}, {0x11d66, 0x11d66}, {0x11d69, 0x11d69}, {0x11d8f, 0x11d8f}, {0x11d92, 0x11d92},
    {0x11d99, 0x11d9f}, {0x11daa, 0x11edf}, {0x11ef9, 0x11faf}, {0x11fb1, 0x11fbf}, {0x11ff2, 0x11ffe},
    {0x1239a, 0x123ff}, {0x1246f, 0x1246f}, {0x12475, 0x1247f}, {0x12544, 0x12f8f}, {0x12ff3, 0x12fff},
    {0x1342f, 0x143ff}, {0x14647, 0x167ff}, {0x16a39, 0x16a3f}, {0x16a5f, 0x16a5f}, {0x16a6a, 0x16a6d},
    {0x16abf, 0x16abf}, {0x16aca, 0x16acf}, {0x16aee, 0x16aef}, {0x16af6, 0x16aff}, {0x16b46, 0x16b4f},
    {0x16b5a, 0x16b5a}, {0x16b62, 0x16b62}, {0x16b78, 0x16b7c}, {0x16b90, 0x16e3f}, {0x16e9b, 0x16eff},
    {0x16f4b, 0x16f4e}, {0x16f88, 0x16f8e}, {0x16fa0, 0x16fdf}, {0x16fe5, 0x16fef}, {0x16ff2, 0x16fff},
    {0x187f8, 0x187ff}, {0x18cd6, 0x18cff}, {0x18d09, 0x1afef}, {0x1aff4, 0x1aff4}, {0x1affc, 0x1affc},
    {0x1afff, 0x1afff}, {0x1b123, 0x1b14f}, {0x1b153, 0x1b163}, {0x1b168, 0x1b16f}, {0x1b2fc, 0x1bbff},
    {0x1bc6b, 0x1bc6f}, {0x1bc7d, 0x1bc7f}, {0x1bc89, 0x1bc8f}, {0x1bc9a, 0x1bc9b}, {0x1bca0, 0x1ceff},
    {0x1cf2e, 0x1cf2f}, {0x1cf47, 0x1cf4f}, {0x1cfc4, 0x1cfff}, {0x1d0f6, 0x1d0ff}, {0x1d127, 0x1d128},
    {0x1d173, 0x1d17a}, {0x1d1eb, 0x1d1ff}, {0x1d246, 0x1d2df}, {0x1d2f4, 0x1d2ff}, {0x1d357, 0x1d35f},
    {0x1d379, 0x1d3ff}, {0x1d455, 0x1d455}, {0x1d49d, 0x1d49d}, {0x1d4a0, 0x1d4a1}, {0x1d4a3, 0x1d4a4},
    {0x1d4a7, 0x1d4a8}, {0x1d4ad, 0x1d4ad}, {0x1d4ba, 0x1d4ba}, {0x1d4bc, 0x1d4bc}, {0x1d4c4, 0x1d4c4},
    {0x1d506, 0x1d506}, {0x1d50b, 0x1d50c}, {0x1d515, 0x1d515}, {0x1d51d, 0x1d51d}, {0x1d53a, 0x1d53a},
    {0x1d53f, 0x1d53f}, {0x1d545, 0x1d545}, {0x1d547, 0x1d549}, {0x1d551, 0x1d551}, {0x1d6a6, 0x1d6a7},
    {0x1d7cc, 0x1d7cd}, {0x1da8c, 0x1da9a}, {0x1daa0, 0x1daa0}, {0x1dab0, 0x1deff}, {0x1df1f, 0x1dfff},
    {0x1e007, 0x1e007}, {0x1e019, 0x1e01a}, {0x1e022, 0x1e022}, {0x1e025, 0x1e025}, {0x1e02b, 0x1e0ff},
    {0x1e12d, 0x1e12f}, {0x1e13e, 0x1e13f}, {0x1e14a, 0x1e14d}, {0x1e150, 0x1e28f}, {0x1e2af, 0x1e2bf},
    {0x1e2fa, 0x1e2fe}, {0x1e300, 0x1e7df}, {0x1e7e7, 0x1e7e7}, {0x1e7ec, 0x1e7ec}, {0x1e7ef, 0x1e7ef},
    {0x1e7ff, 0x1e7ff}, {0x1e8c5, 0x1e8c6}, {0x1e8d7, 0x1e8ff}, {0x1e94c, 0x1e94f}, {0x1e95a, 0x1e95d},
    {0x1e960, 0x1ec70}, {0x1ecb5, 0x1ed00}, {0x1ed3e, 0x1edff}, {0x1ee04, 0x1ee04}, {0x1ee20, 0x1ee20},
    {0x1ee23, 0x1ee23}, {0x1ee25, 0x1ee26}, {0x1ee28, 0x1ee28}, {0x1ee33, 0x1ee33}, {0x1ee38, 0x1ee38},
    {0x1ee3a, 0x1ee3a}, {0x1ee3c, 0x1ee41}, {0x1ee43, 0x1ee46}, {0x1ee48, 0x1ee48}, {0x1ee4a, 0x1ee4a},
    {0x1ee4c, 0x1ee4c}, {0x1ee50, 0x1ee50}, {0x1ee53, 0x1ee53}, {0x1ee55, 0x1ee56}, {0x1ee58, 0x1ee58},
    {0x1ee5a, 0x1ee5a}, {0x1ee5c, 0x1ee5c}, {0x1ee5e, 0x1ee5e}, {0x1ee60, 0x1ee60}, {0x1ee63, 0x1ee63},
    {0x1ee65, 0x1ee66}, {0x1ee6b, 0x1ee6b}, {0x1ee73, 0x1ee73}, {0x1ee78, 0x1ee78}, {0x1ee7d, 0x1ee7d},
    {0x1ee7f, 0x1ee7f}, {0x1ee8a, 0x1ee8a}, {0x1ee9c, 0x1eea0}, {0x1eea4, 0x1eea4}, {0x1eeaa, 0x1eeaa},
    {0x1eebc, 0x1eeef}, {0x1eef2, 0x1efff}, {0x1f02c, 0x1f02f}, {0x1f094, 0x1f09f}, {0x1f0af, 0x1f0b0},
    {0x1f0c0, 0x1f0c0}, {0x1f0d0, 0x1f0d0}, {0x1f0f6, 0x1f0ff}, {0x1f1ae, 0x1f1e5}, {0x1f203, 0x1f20f},
    {0x1f23c, 0x1f23f}, {0x1f249, 0x1f24f}, {0x1f252, 0x1f25f}, {0x1f266, 0x1f2ff}, {0x1f6d8, 0x1f6dc},
    {0x1f6ed, 0x1f6ef}, {0x1f6fd, 0x1f6ff}, {0x1f774, 0x1f77f}, {0x1f7d9, 0x1f7df}, {0x1f7ec, 0x1f7ef},
    {0x1f7f1, 0x1f7ff}, {0x1f80c, 0x1f80f}, {0x1f848, 0x1f84f}, {0x1f85a, 0x1f85f}, {0x1f888, 0x1f88f},
    {0x1f8ae, 0x1f8af}, {0x1f8b2, 0x1f8ff}, {0x1fa54, 0x1fa5f}, {0x1fa6e, 0x1fa6f}, {0x1fa75, 0x1fa77},
    {0x1fa7d, 0x1fa7f}, {0x1fa87, 0x1fa8f}, {0x1faad, 0x1faaf}, {0x1fabb, 0x1fabf}, {0x1fac6, 0x1facf},
    {0x1fada, 0x1fadf}, {0x1fae8, 0x1faef}, {0x1faf7, 0x1faff}, {0x1fb93, 0x1fb93}, {0x1fbcb, 0x1fbef},
    {0x1fbfa, 0x1ffff}, {0x2a6e0, 0x2a6ff}, {0x2b739, 0x2b73f}, {0x2b81e, 0x2b81f}, {0x2cea2, 0x2ceaf},
    {0x2ebe1, 0x2f7ff}, {0x2fa1e, 0x2ffff}, {0x3134b, 0xe00ff}, {0xe01f0, 0x10ffff},
}};

// Code points str.isspace() accepts (str.strip() and float() strip them).
constexpr std::array<char32_t, 29> kPySpace{0x9, 0xa, 0xb, 0xc, 0xd, 0x1c, 0x1d, 0x1e, 0x1f, 0x20, 0x85, 0xa0, 0x1680, 0x2000, 0x2001, 0x2002, 0x2003, 0x2004, 0x2005, 0x2006, 0x2007, 0x2008, 0x2009, 0x200a, 0x2028, 0x2029, 0x202f, 0x205f, 0x3000};

// The zeros of the Unicode decimal digit runs (category Nd, ten in a row): float() reads any of them.
constexpr std::array<char32_t, 66> kDecimalZeros{
    0x30, 0x660, 0x6f0, 0x7c0, 0x966, 0x9e6, 0xa66, 0xae6, 0xb66, 0xbe6, 0xc66, 0xce6, 0xd66, 0xde6, 0xe50, 0xed0,
    0xf20, 0x1040, 0x1090, 0x17e0, 0x1810, 0x1946, 0x19d0, 0x1a80, 0x1a90, 0x1b50, 0x1bb0, 0x1c40, 0x1c50, 0xa620,
    0xa8d0, 0xa900, 0xa9d0, 0xa9f0, 0xaa50, 0xabf0, 0xff10, 0x104a0, 0x10d30, 0x11066, 0x110f0, 0x11136, 0x111d0,
    0x112f0, 0x11450, 0x114d0, 0x11650, 0x116c0, 0x11730, 0x118e0, 0x11950, 0x11c50, 0x11d50, 0x11da0, 0x16a60,
    0x16ac0, 0x16b50, 0x1d7ce, 0x1d7d8, 0x1d7e2, 0x1d7ec, 0x1d7f6, 0x1e140, 0x1e2f0, 0x1e950, 0x1fbf0,
};

// Identifier characters beyond ASCII whose NFKC form is one ASCII letter, digit or '_' (Python
// normalises identifiers, so 'ｐｉ' is pi): {first, last, ASCII of first, may start an identifier}.
constexpr std::array<IdentRange, 147> kIdentAscii{{
    {0xaa, 0xaa, 'a', true}, {0xba, 0xba, 'o', true}, {0x17f, 0x17f, 's', true}, {0x2b0, 0x2b0, 'h', true},
    {0x2b2, 0x2b2, 'j', true}, {0x2b3, 0x2b3, 'r', true}, {0x2b7, 0x2b7, 'w', true}, {0x2b8, 0x2b8, 'y', true},
    {0x2e1, 0x2e1, 'l', true}, {0x2e2, 0x2e2, 's', true}, {0x2e3, 0x2e3, 'x', true}, {0x1d2c, 0x1d2c, 'A', true},
    {0x1d2e, 0x1d2e, 'B', true}, {0x1d30, 0x1d31, 'D', true}, {0x1d33, 0x1d3a, 'G', true},
    {0x1d3c, 0x1d3c, 'O', true}, {0x1d3e, 0x1d3e, 'P', true}, {0x1d3f, 0x1d3f, 'R', true},
    {0x1d40, 0x1d41, 'T', true}, {0x1d42, 0x1d42, 'W', true}, {0x1d43, 0x1d43, 'a', true},
    {0x1d47, 0x1d47, 'b', true}, {0x1d48, 0x1d49, 'd', true}, {0x1d4d, 0x1d4d, 'g', true},
    {0x1d4f, 0x1d4f, 'k', true}, {0x1d50, 0x1d50, 'm', true}, {0x1d52, 0x1d52, 'o', true},
    {0x1d56, 0x1d56, 'p', true}, {0x1d57, 0x1d58, 't', true}, {0x1d5b, 0x1d5b, 'v', true},
    {0x1d62, 0x1d62, 'i', true}, {0x1d63, 0x1d63, 'r', true}, {0x1d64, 0x1d65, 'u', true},
    {0x1d9c, 0x1d9c, 'c', true}, {0x1da0, 0x1da0, 'f', true}, {0x1dbb, 0x1dbb, 'z', true},
    {0x2071, 0x2071, 'i', true}, {0x207f, 0x207f, 'n', true}, {0x2090, 0x2090, 'a', true},
    {0x2091, 0x2091, 'e', true}, {0x2092, 0x2092, 'o', true}, {0x2093, 0x2093, 'x', true},
    {0x2095, 0x2095, 'h', true}, {0x2096, 0x2099, 'k', true}, {0x209a, 0x209a, 'p', true},
    {0x209b, 0x209c, 's', true}, {0x2102, 0x2102, 'C', true}, {0x210a, 0x210a, 'g', true},
    {0x210b, 0x210b, 'H', true}, {0x210c, 0x210c, 'H', true}, {0x210d, 0x210d, 'H', true},
    {0x210e, 0x210e, 'h', true}, {0x2110, 0x2110, 'I', true}, {0x2111, 0x2111, 'I', true},
    {0x2112, 0x2112, 'L', true}, {0x2113, 0x2113, 'l', true}, {0x2115, 0x2115, 'N', true},
    {0x2119, 0x211b, 'P', true}, {0x211c, 0x211c, 'R', true}, {0x211d, 0x211d, 'R', true},
    {0x2124, 0x2124, 'Z', true}, {0x2128, 0x2128, 'Z', true}, {0x212a, 0x212a, 'K', true},
    {0x212c, 0x212d, 'B', true}, {0x212f, 0x212f, 'e', true}, {0x2130, 0x2131, 'E', true},
    {0x2133, 0x2133, 'M', true}, {0x2134, 0x2134, 'o', true}, {0x2139, 0x2139, 'i', true},
    {0x2145, 0x2145, 'D', true}, {0x2146, 0x2147, 'd', true}, {0x2148, 0x2149, 'i', true},
    {0x2160, 0x2160, 'I', true}, {0x2164, 0x2164, 'V', true}, {0x2169, 0x2169, 'X', true},
    {0x216c, 0x216c, 'L', true}, {0x216d, 0x216e, 'C', true}, {0x216f, 0x216f, 'M', true},
    {0x2170, 0x2170, 'i', true}, {0x2174, 0x2174, 'v', true}, {0x2179, 0x2179, 'x', true},
    {0x217c, 0x217c, 'l', true}, {0x217d, 0x217e, 'c', true}, {0x217f, 0x217f, 'm', true},
    {0x2c7c, 0x2c7c, 'j', true}, {0x2c7d, 0x2c7d, 'V', true}, {0xa7f2, 0xa7f2, 'C', true},
    {0xa7f3, 0xa7f3, 'F', true}, {0xa7f4, 0xa7f4, 'Q', true}, {0xfe33, 0xfe33, '_', false},
    {0xfe34, 0xfe34, '_', false}, {0xfe4d, 0xfe4d, '_', false}, {0xfe4e, 0xfe4e, '_', false},
    {0xfe4f, 0xfe4f, '_', false}, {0xff10, 0xff19, '0', false}, {0xff21, 0xff3a, 'A', true},
    {0xff3f, 0xff3f, '_', false}, {0xff41, 0xff5a, 'a', true}, {0x107a5, 0x107a5, 'q', true},
    {0x1d400, 0x1d419, 'A', true}, {0x1d41a, 0x1d433, 'a', true}, {0x1d434, 0x1d44d, 'A', true},
    {0x1d44e, 0x1d454, 'a', true}, {0x1d456, 0x1d467, 'i', true}, {0x1d468, 0x1d481, 'A', true},
    {0x1d482, 0x1d49b, 'a', true}, {0x1d49c, 0x1d49c, 'A', true}, {0x1d49e, 0x1d49f, 'C', true},
    {0x1d4a2, 0x1d4a2, 'G', true}, {0x1d4a5, 0x1d4a6, 'J', true}, {0x1d4a9, 0x1d4ac, 'N', true},
    {0x1d4ae, 0x1d4b5, 'S', true}, {0x1d4b6, 0x1d4b9, 'a', true}, {0x1d4bb, 0x1d4bb, 'f', true},
    {0x1d4bd, 0x1d4c3, 'h', true}, {0x1d4c5, 0x1d4cf, 'p', true}, {0x1d4d0, 0x1d4e9, 'A', true},
    {0x1d4ea, 0x1d503, 'a', true}, {0x1d504, 0x1d505, 'A', true}, {0x1d507, 0x1d50a, 'D', true},
    {0x1d50d, 0x1d514, 'J', true}, {0x1d516, 0x1d51c, 'S', true}, {0x1d51e, 0x1d537, 'a', true},
    {0x1d538, 0x1d539, 'A', true}, {0x1d53b, 0x1d53e, 'D', true}, {0x1d540, 0x1d544, 'I', true},
    {0x1d546, 0x1d546, 'O', true}, {0x1d54a, 0x1d550, 'S', true}, {0x1d552, 0x1d56b, 'a', true},
    {0x1d56c, 0x1d585, 'A', true}, {0x1d586, 0x1d59f, 'a', true}, {0x1d5a0, 0x1d5b9, 'A', true},
    {0x1d5ba, 0x1d5d3, 'a', true}, {0x1d5d4, 0x1d5ed, 'A', true}, {0x1d5ee, 0x1d607, 'a', true},
    {0x1d608, 0x1d621, 'A', true}, {0x1d622, 0x1d63b, 'a', true}, {0x1d63c, 0x1d655, 'A', true},
    {0x1d656, 0x1d66f, 'a', true}, {0x1d670, 0x1d689, 'A', true}, {0x1d68a, 0x1d6a3, 'a', true},
    {0x1d7ce, 0x1d7d7, '0', false}, {0x1d7d8, 0x1d7e1, '0', false}, {0x1d7e2, 0x1d7eb, '0', false},
    {0x1d7ec, 0x1d7f5, '0', false}, {0x1d7f6, 0x1d7ff, '0', false}, {0x1fbf0, 0x1fbf9, '0', false},
}};

// ------------------------------------------------------------------------------------------------
// Text

constexpr double kPi = 3.141592653589793238;  // math.pi
constexpr std::size_t kMaxSceneBytes = 1 << 20;  // MAX_SCENE_BYTES
constexpr std::size_t kMaxPanels = 36;           // MAX_PANELS (also the most series)
constexpr std::size_t kMaxSeriesPoints = 200;    // MAX_SERIES_POINTS
constexpr std::size_t kMaxExpr = 200;            // _MAX_EXPR

[[noreturn]] void fail(const std::string& msg) { throw std::invalid_argument(msg); }

/// Code points of UTF-8 text (toml++ and load_sweep_scene have validated it; a stray byte is kept as
/// itself so nothing here can read past the end).
std::u32string decode(std::string_view s) {
    std::u32string out;
    out.reserve(s.size());
    for (std::size_t i = 0; i < s.size();) {
        const auto b = static_cast<unsigned char>(s[i]);
        const int n = b < 0x80 ? 0 : b >= 0xF0 ? 3 : b >= 0xE0 ? 2 : b >= 0xC0 ? 1 : -1;
        if (n <= 0 || i + n >= s.size()) {
            out.push_back(b);
            ++i;
            continue;
        }
        char32_t c = b & (0x3F >> n);
        for (int k = 1; k <= n; ++k) c = (c << 6) | (static_cast<unsigned char>(s[i + k]) & 0x3F);
        out.push_back(c);
        i += n + 1;
    }
    return out;
}

/// Offset of the first byte Python's strict UTF-8 decoder refuses (the start of the bad sequence,
/// as UnicodeDecodeError.start), or npos for valid UTF-8.
std::size_t utf8_error(std::string_view s) {
    const auto byte = [&](std::size_t i) { return i < s.size() ? static_cast<unsigned char>(s[i]) : 0x100u; };
    for (std::size_t i = 0; i < s.size();) {
        const unsigned b = byte(i);
        if (b < 0x80) {
            ++i;
            continue;
        }
        int n;
        unsigned lo = 0x80, hi = 0xBF;  // the allowed range of the second byte
        if (b >= 0xC2 && b <= 0xDF) n = 1;
        else if (b >= 0xE0 && b <= 0xEF) n = 2, lo = b == 0xE0 ? 0xA0 : 0x80, hi = b == 0xED ? 0x9F : 0xBF;
        else if (b >= 0xF0 && b <= 0xF4) n = 3, lo = b == 0xF0 ? 0x90 : 0x80, hi = b == 0xF4 ? 0x8F : 0xBF;
        else return i;
        if (byte(i + 1) < lo || byte(i + 1) > hi) return i;
        for (int k = 2; k <= n; ++k)
            if (byte(i + k) < 0x80 || byte(i + k) > 0xBF) return i;
        i += n + 1;
    }
    return std::string::npos;
}

bool py_isspace(char32_t c) { return std::find(kPySpace.begin(), kPySpace.end(), c) != kPySpace.end(); }

bool py_isprintable(char32_t c) {
    const auto it = std::upper_bound(kNonPrintable.begin(), kNonPrintable.end(), c,
                                     [](char32_t x, const std::pair<char32_t, char32_t>& r) { return x < r.first; });
    return it == kNonPrintable.begin() || c > std::prev(it)->second;
}

/// The ASCII digit of a Unicode decimal digit (category Nd), or -1.
int decimal_digit(char32_t c) {
    const auto it = std::upper_bound(kDecimalZeros.begin(), kDecimalZeros.end(), c);
    if (it == kDecimalZeros.begin()) return -1;
    const char32_t zero = *std::prev(it);
    return c - zero < 10 ? static_cast<int>(c - zero) : -1;
}

bool is_ascii_digit(char32_t c) { return c >= '0' && c <= '9'; }
bool is_ascii_alpha(char32_t c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); }

// ------------------------------------------------------------------------------------------------
// Python's repr() and formats

/// repr(float): the shortest digits that round-trip, in fixed notation for exponents -4 <= e < 16.
std::string py_float(double v) {
    if (std::isnan(v)) return "nan";
    if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::scientific);
    std::string s(buf, r.ptr);  // [-]d[.ddd]e(+|-)XX
    std::string sign;
    if (s[0] == '-') sign = "-", s.erase(0, 1);
    const auto e = s.find('e');
    const int exp = std::atoi(s.c_str() + e + 1);
    std::string digits = s.substr(0, e);
    digits.erase(std::remove(digits.begin(), digits.end(), '.'), digits.end());
    const int n = static_cast<int>(digits.size()), decpt = exp + 1;
    std::string out;
    if (decpt > -4 && decpt <= 16) {
        if (decpt <= 0) out = "0." + std::string(-decpt, '0') + digits;
        else if (decpt >= n) out = digits + std::string(decpt - n, '0') + ".0";
        else out = digits.substr(0, decpt) + "." + digits.substr(decpt);
    } else {
        out = digits.substr(0, 1) + (n > 1 ? "." + digits.substr(1) : "");
        char eb[16];
        std::snprintf(eb, sizeof eb, "e%c%02d", exp < 0 ? '-' : '+', std::abs(exp));
        out += eb;
    }
    return sign + out;
}

/// format(v, '.6g'): C's %.6g, but NaN without a sign as Python writes it.
std::string py_g6(double v) {
    if (std::isnan(v)) return "nan";
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
}

void append_utf8(std::string& out, char32_t c) {
    if (c < 0x80) {
        out += static_cast<char>(c);
    } else if (c < 0x800) {
        out += static_cast<char>(0xC0 | (c >> 6));
        out += static_cast<char>(0x80 | (c & 0x3F));
    } else if (c < 0x10000) {
        out += static_cast<char>(0xE0 | (c >> 12));
        out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (c & 0x3F));
    } else {
        out += static_cast<char>(0xF0 | (c >> 18));
        out += static_cast<char>(0x80 | ((c >> 12) & 0x3F));
        out += static_cast<char>(0x80 | ((c >> 6) & 0x3F));
        out += static_cast<char>(0x80 | (c & 0x3F));
    }
}

/// repr(str): single quotes unless the text has ' and no ", escapes for the quote, backslash,
/// \t \n \r, other control characters and whatever str.isprintable() refuses.
std::string py_str(std::string_view s) {
    const std::u32string u = decode(s);
    const bool has1 = u.find(U'\'') != std::u32string::npos, has2 = u.find(U'"') != std::u32string::npos;
    const char q = has1 && !has2 ? '"' : '\'';
    std::string out(1, q);
    for (const char32_t c : u) {
        char buf[16];
        if (c == static_cast<char32_t>(q) || c == U'\\') out += '\\', out += static_cast<char>(c);
        else if (c == U'\t') out += "\\t";
        else if (c == U'\n') out += "\\n";
        else if (c == U'\r') out += "\\r";
        else if (c < 0x20 || c == 0x7F) std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned>(c)), out += buf;
        else if (c < 0x7F || py_isprintable(c)) append_utf8(out, c);
        else if (c <= 0xFF) std::snprintf(buf, sizeof buf, "\\x%02x", static_cast<unsigned>(c)), out += buf;
        else if (c <= 0xFFFF) std::snprintf(buf, sizeof buf, "\\u%04x", static_cast<unsigned>(c)), out += buf;
        else std::snprintf(buf, sizeof buf, "\\U%08x", static_cast<unsigned>(c)), out += buf;
    }
    return out + q;
}

/// A table's entries in the order tomllib's dict has them (where each key first appears): toml++
/// keeps a table sorted by key, and Python's messages list unknown keys and dict reprs in file order.
std::vector<std::pair<std::string_view, const toml::node*>> entries(const toml::table& t) {
    struct E {
        toml::source_position pos;
        std::string_view key;
        const toml::node* node;
    };
    std::vector<E> v;
    for (const auto& [k, n] : t) v.push_back({k.source().begin, k.str(), &n});
    std::stable_sort(v.begin(), v.end(), [](const E& a, const E& b) { return a.pos < b.pos; });
    std::vector<std::pair<std::string_view, const toml::node*>> out;
    for (const auto& e : v) out.emplace_back(e.key, e.node);
    return out;
}

std::string py_timedelta(long seconds) {
    long days = seconds / 86400, rest = seconds % 86400;
    if (rest < 0) rest += 86400, --days;
    std::string args;
    if (days) args += "days=" + std::to_string(days);
    if (rest) args += std::string(args.empty() ? "" : ", ") + "seconds=" + std::to_string(rest);
    return "datetime.timedelta(" + (args.empty() ? "0" : args) + ")";
}

std::string py_time_args(const toml::time& t) {
    std::string s = std::to_string(t.hour) + ", " + std::to_string(t.minute);
    const unsigned us = t.nanosecond / 1000;  // tomllib keeps microseconds, truncated
    if (t.second || us) s += ", " + std::to_string(t.second);
    if (us) s += ", " + std::to_string(us);
    return s;
}

std::string py_date_args(const toml::date& d) {
    return std::to_string(d.year) + ", " + std::to_string(d.month) + ", " + std::to_string(d.day);
}

/// repr() of the value tomllib returns for a TOML node (int, float, str, bool, list, dict and
/// the datetime classes).
std::string py_repr(const toml::node& n) {
    switch (n.type()) {
        case toml::node_type::string: return py_str(n.as_string()->get());
        case toml::node_type::integer: return std::to_string(n.as_integer()->get());
        case toml::node_type::floating_point: return py_float(n.as_floating_point()->get());
        case toml::node_type::boolean: return n.as_boolean()->get() ? "True" : "False";
        case toml::node_type::array: {
            std::string s = "[";
            for (const auto& e : *n.as_array()) s += (s.size() > 1 ? ", " : "") + py_repr(e);
            return s + "]";
        }
        case toml::node_type::table: {
            std::string s = "{";
            for (const auto& [k, v] : entries(*n.as_table())) s += (s.size() > 1 ? ", " : "") + py_str(k) + ": " + py_repr(*v);
            return s + "}";
        }
        case toml::node_type::date: return "datetime.date(" + py_date_args(n.as_date()->get()) + ")";
        case toml::node_type::time: return "datetime.time(" + py_time_args(n.as_time()->get()) + ")";
        case toml::node_type::date_time: {
            const toml::date_time& dt = n.as_date_time()->get();
            std::string s = "datetime.datetime(" + py_date_args(dt.date) + ", " + py_time_args(dt.time);
            if (dt.offset) {
                const long sec = 60L * dt.offset->minutes;
                s += ", tzinfo=" + (sec == 0 ? std::string("datetime.timezone.utc")
                                             : "datetime.timezone(" + py_timedelta(sec) + ")");
            }
            return s + ")";
        }
        default: return "None";
    }
}

/// repr() of a list of str (e.g. ['atol', 'rtol']).
std::string py_list(const std::vector<std::string_view>& v) {
    std::string s = "[";
    for (const auto& x : v) s += (s.size() > 1 ? ", " : "") + py_str(x);
    return s + "]";
}

/// ', '.join(repr(c) for c in choices).
std::string py_choices(const std::vector<std::string_view>& v) {
    std::string s;
    for (const auto& x : v) s += (s.empty() ? "" : ", ") + py_str(x);
    return s;
}

// ------------------------------------------------------------------------------------------------
// Numbers as Python reads them

/// A correctly rounded double from decimal digits times 10^exp10 (strtod without a decimal point,
/// so the C locale's separator cannot matter); exp10 is clamped far beyond the double range.
double decimal_value(const std::string& digits, long long exp10) {
    const bool zero = digits.find_first_not_of('0') == std::string::npos;
    if (zero) return 0.0;
    exp10 = std::clamp(exp10, -100000LL, 100000LL);
    const std::string s = digits + "e" + std::to_string(exp10);
    return std::strtod(s.c_str(), nullptr);
}

/// An integer's exact bits to the nearest double (ties to even, as int.__float__); inf if it overflows.
double bits_value(const std::string& bits) {
    const auto first = bits.find('1');
    if (first == std::string::npos) return 0.0;
    const std::string b = bits.substr(first);
    if (b.size() > 1100) return HUGE_VAL;
    const std::size_t keep = std::min<std::size_t>(b.size(), 53);
    std::uint64_t m = 0;
    for (std::size_t i = 0; i < keep; ++i) m = (m << 1) | static_cast<std::uint64_t>(b[i] == '1');
    if (b.size() > keep) {
        const bool half = b[keep] == '1', sticky = b.find('1', keep + 1) != std::string::npos;
        if (half && (sticky || (m & 1))) ++m;
    }
    return std::ldexp(static_cast<double>(m), static_cast<int>(b.size() - keep));
}

/// float(s) for a str as Python 3.11 reads it: Unicode spaces and decimal digits first become
/// ASCII, underscores only between digits, spaces stripped, then a decimal (no hex) or
/// inf/infinity/nan with an optional sign; nullopt where Python raises ValueError.
std::optional<double> py_float_of(std::string_view text) {
    std::string s;
    for (const char32_t c : decode(text)) {
        if (py_isspace(c)) s += ' ';
        else if (c < 0x80) s += static_cast<char>(c);
        else if (const int d = decimal_digit(c); d >= 0) s += static_cast<char>('0' + d);
        else return std::nullopt;
    }
    if (s.find('_') != std::string::npos) {
        std::string t;
        char prev = 0;
        for (const char c : s) {
            if (c == '_' && !is_ascii_digit(prev)) return std::nullopt;
            if (c != '_' && prev == '_' && !is_ascii_digit(c)) return std::nullopt;
            if (c != '_') t += c;
            prev = c;
        }
        if (prev == '_') return std::nullopt;
        s = t;
    }
    const auto ws = [](char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\v' || c == '\f' || c == '\r'; };
    std::size_t a = 0, b = s.size();
    while (a < b && ws(s[a])) ++a;
    while (b > a && ws(s[b - 1])) --b;
    std::string t = s.substr(a, b - a);
    double sign = 1.0;
    std::size_t i = 0;
    if (i < t.size() && (t[i] == '+' || t[i] == '-')) sign = t[i] == '-' ? -1.0 : 1.0, ++i;
    std::string rest = t.substr(i);
    std::transform(rest.begin(), rest.end(), rest.begin(), [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); });
    if (rest == "inf" || rest == "infinity") return sign * HUGE_VAL;
    if (rest == "nan") return std::nan("");
    std::string digits, exp;
    std::size_t j = 0, frac = 0;
    bool any = false;
    while (j < rest.size() && is_ascii_digit(rest[j])) digits += rest[j++], any = true;
    if (j < rest.size() && rest[j] == '.') {
        ++j;
        while (j < rest.size() && is_ascii_digit(rest[j])) digits += rest[j++], ++frac, any = true;
    }
    if (!any) return std::nullopt;
    long long e10 = 0;
    if (j < rest.size() && rest[j] == 'e') {
        ++j;
        bool neg = false;
        if (j < rest.size() && (rest[j] == '+' || rest[j] == '-')) neg = rest[j] == '-', ++j;
        if (j >= rest.size() || !is_ascii_digit(rest[j])) return std::nullopt;
        while (j < rest.size() && is_ascii_digit(rest[j])) e10 = std::min(e10 * 10 + (rest[j++] - '0'), 1000000LL);
        if (neg) e10 = -e10;
    }
    if (j != rest.size()) return std::nullopt;
    return sign * decimal_value(digits, e10 - static_cast<long long>(frac));
}

// ------------------------------------------------------------------------------------------------
// The expressions of _real: ast.parse(value, mode="eval") walked by _eval_expr over floats. Every
// failure gives the same message in Python (syntax, an unsupported node, ZeroDivisionError, math
// domain and range errors, a complex power), so here one exception stands for them all; what must
// match exactly is which texts fail, which evaluate to a non-finite float, and the bits of the rest.

struct ExprError {};

/// DOUBLE_IS_ODD_INTEGER of CPython's float_pow.
bool odd_integer(double x) { return std::fmod(std::fabs(x), 2.0) == 1.0; }

/// float.__pow__ of CPython 3.11: its own special cases, then the C library's pow and its errno (a
/// negative base to a fractional power is a complex number in Python, which float() refuses).
double py_pow(double v, double w) {
    if (w == 0) return 1.0;
    if (std::isnan(v)) return v;
    if (std::isnan(w)) return v == 1.0 ? 1.0 : w;
    if (std::isinf(w)) {
        const double a = std::fabs(v);
        if (a == 1.0) return 1.0;
        return (w > 0.0) == (a > 1.0) ? std::fabs(w) : 0.0;
    }
    if (std::isinf(v)) {
        const bool odd = odd_integer(w);
        if (w > 0.0) return odd ? v : std::fabs(v);
        return odd ? std::copysign(0.0, v) : 0.0;
    }
    if (v == 0.0) {
        if (w < 0.0) throw ExprError{};  // ZeroDivisionError
        return odd_integer(w) ? v : 0.0;
    }
    bool negate = false;
    if (v < 0.0) {
        if (w != std::floor(w)) throw ExprError{};  // a complex result
        v = -v;
        negate = odd_integer(w);
    }
    if (v == 1.0) return negate ? -1.0 : 1.0;
    errno = 0;
    const double x = std::pow(v, w);
    int err = errno;
    if (err == 0 && (x == HUGE_VAL || x == -HUGE_VAL)) err = ERANGE;  // _Py_ADJUST_ERANGE1
    else if (err == ERANGE && x == 0.0) err = 0;
    if (err != 0) throw ExprError{};  // OverflowError
    return negate ? -x : x;
}

/// math_1 of CPython's math module (sqrt, sin, cos, acos): a NaN from a number or an infinity from a
/// finite argument is an error, as is an errno other than an underflow.
double py_math(double (*f)(double), double x) {
    errno = 0;
    const double r = f(x);
    const int err = errno;
    if (std::isnan(r) && !std::isnan(x)) throw ExprError{};
    if (std::isinf(r) && std::isfinite(x)) throw ExprError{};
    if (std::isfinite(r) && err != 0 && !(err == ERANGE && std::fabs(r) < 1.5)) throw ExprError{};
    return r;
}

/// The ASCII character an identifier character stands for after Python's NFKC normalisation, or 0.
char ident_char(char32_t c, bool first) {
    if (is_ascii_alpha(c) || c == U'_') return static_cast<char>(c);
    if (is_ascii_digit(c)) return first ? 0 : static_cast<char>(c);
    if (c < 0x80) return 0;
    const auto it = std::upper_bound(kIdentAscii.begin(), kIdentAscii.end(), c,
                                     [](char32_t x, const IdentRange& r) { return x < r.first; });
    if (it == kIdentAscii.begin()) return 0;
    const IdentRange& r = *std::prev(it);
    if (c > r.last || (first && !r.start)) return 0;
    return static_cast<char>(r.ascii + (c - r.first));
}

/// Python's tokenizer (CPython 3.11: indentation, continuation lines, comments, number literals)
/// and the part of its grammar whose trees _eval_expr accepts, evaluated as it is parsed.
class Expression {
public:
    explicit Expression(const std::u32string& text) {
        // Source text reaches the tokenizer with \r\n and \r read as \n; a NUL is refused outright.
        for (std::size_t i = 0; i < text.size(); ++i) {
            if (text[i] == 0) throw ExprError{};
            if (text[i] == U'\r') {
                s_ += U'\n';
                if (i + 1 < text.size() && text[i + 1] == U'\n') ++i;
            } else {
                s_ += text[i];
            }
        }
    }

    double evaluate() {
        tokenize();
        const Item it = sum();
        if (peek().kind != Kind::Newline && peek().kind != Kind::End) throw ExprError{};
        return value_of(it);
    }

private:
    enum class Kind { Number, Name, Op, Newline, End };
    struct Token {
        Kind kind;
        double value = 0;
        std::string text;
    };
    // A parsed operand: a number, or a bare name (still a name through parentheses: "(sqrt)(4)" calls
    // sqrt) that becomes pi, OMEGA_G or a function by how it is used.
    struct Item {
        bool is_name = false;
        double value = 0;
        std::string name;
    };

    std::u32string s_;
    std::size_t i_ = 0;
    std::vector<Token> toks_;
    std::size_t pos_ = 0;

    char32_t at(std::size_t j) const { return j < s_.size() ? s_[j] : 0; }

    /// A backslash must end its line, and a line must follow (CPython's tok_continuation_line).
    void continuation() {
        if (at(i_ + 1) != U'\n') throw ExprError{};
        i_ += 2;
        if (i_ >= s_.size()) throw ExprError{};
    }

    void tokenize() {
        int level = 0;
        bool bol = true, ended = false;
        for (;;) {
            bool blank = false;
            if (bol) {
                // Indentation: the first backslash-joined column, else the line's own, must be 0
                // for a line with code (one expression: any indent is an IndentationError).
                bol = false;
                int col = 0, cont = 0;
                for (;;) {
                    const char32_t c = at(i_);
                    if (c == U' ') ++col, ++i_;
                    else if (c == U'\t') col = (col / 8 + 1) * 8, ++i_;
                    else if (c == U'\f') col = 0, ++i_;
                    else if (c == U'\\') {
                        if (!cont) cont = col;
                        continuation();
                    } else break;
                }
                blank = at(i_) == U'#' || at(i_) == U'\n';
                if (!blank && level == 0 && (cont ? cont : col) != 0) throw ExprError{};
            }
            for (;;) {
                while (at(i_) == U' ' || at(i_) == U'\t' || at(i_) == U'\f') ++i_;
                if (at(i_) == U'#')
                    while (i_ < s_.size() && s_[i_] != U'\n') ++i_;
                if (i_ >= s_.size()) {
                    if (level) throw ExprError{};
                    toks_.push_back({Kind::End, 0, {}});
                    return;
                }
                const char32_t c = s_[i_];
                if (c == U'\n') {
                    ++i_;
                    bol = true;
                    if (!blank && level == 0) toks_.push_back({Kind::Newline, 0, {}}), ended = true;
                    break;
                }
                if (c == U'\\') {
                    continuation();
                    continue;
                }
                if (ended) throw ExprError{};  // code after the expression's line: a second statement
                if (is_ascii_digit(c) || (c == U'.' && is_ascii_digit(at(i_ + 1)))) {
                    toks_.push_back({Kind::Number, number(), {}});
                } else if (ident_char(c, true) || c >= 0x80) {
                    std::string name;
                    while (at(i_) >= 0x80 || ident_char(at(i_), name.empty())) {
                        const char a = ident_char(at(i_), name.empty());
                        if (!a) throw ExprError{};  // not an identifier, or none that normalises to ASCII
                        name += a;
                        ++i_;
                    }
                    toks_.push_back({Kind::Name, 0, name});
                } else {
                    // Python has more operators, but none that _eval_expr evaluates.
                    std::string op;
                    if (c == U'*' && at(i_ + 1) == U'*') op = "**";
                    else if (c < 0x80 && std::strchr("+-*/(),", static_cast<int>(c))) op = std::string(1, static_cast<char>(c));
                    else throw ExprError{};
                    if (op == "(") ++level;
                    if (op == ")" && level-- == 0) throw ExprError{};  // unmatched ')'
                    i_ += op.size();
                    toks_.push_back({Kind::Op, 0, op});
                }
            }
        }
    }

    /// Digits of tok_decimal_tail: digit runs joined by single underscores.
    void decimal_tail(std::string& digits) {
        for (;;) {
            while (is_ascii_digit(at(i_))) digits += static_cast<char>(at(i_++));
            if (at(i_) != U'_') return;
            ++i_;
            if (!is_ascii_digit(at(i_))) throw ExprError{};
        }
    }

    /// verify_end_of_number: a literal followed by a letter, digit or '_' is an error (and the
    /// keywords Python lets through with a warning only lead to trees _eval_expr refuses).
    void end_of_number() const {
        const char32_t c = at(i_);
        if (is_ascii_alpha(c) || is_ascii_digit(c) || c == U'_' || c >= 0x80) throw ExprError{};
    }

    /// A number literal as float(node.value): ints (any base) exactly rounded and refused when too
    /// large for a double (OverflowError), floats rounded as the parser does (1e400 is inf).
    double number() {
        const char32_t c0 = at(i_), c1 = at(i_ + 1);
        if (c0 == U'0' && (c1 == U'x' || c1 == U'X' || c1 == U'o' || c1 == U'O' || c1 == U'b' || c1 == U'B')) {
            const int base = (c1 == U'x' || c1 == U'X') ? 16 : (c1 == U'o' || c1 == U'O') ? 8 : 2;
            const int width = base == 16 ? 4 : base == 8 ? 3 : 1;
            const auto digit = [&](char32_t c) -> int {
                int d = -1;
                if (is_ascii_digit(c)) d = static_cast<int>(c - U'0');
                else if (c >= U'a' && c <= U'f') d = static_cast<int>(c - U'a') + 10;
                else if (c >= U'A' && c <= U'F') d = static_cast<int>(c - U'A') + 10;
                return d < base ? d : -1;
            };
            i_ += 2;
            std::string bits;
            do {
                if (at(i_) == U'_') ++i_;
                if (digit(at(i_)) < 0) throw ExprError{};
                for (int d; (d = digit(at(i_))) >= 0; ++i_)
                    for (int k = width - 1; k >= 0; --k) bits += ((d >> k) & 1) ? '1' : '0';
            } while (at(i_) == U'_');
            end_of_number();
            const double v = bits_value(bits);
            if (std::isinf(v)) throw ExprError{};
            return v;
        }
        std::string int_digits, frac_digits;
        bool is_float = false;
        long long exp10 = 0;
        if (c0 == U'0') {
            // "0", "00", "0_0"; other digits after leading zeros only before '.', 'e' or 'j'.
            for (;;) {
                if (at(i_) == U'_') {
                    ++i_;
                    if (!is_ascii_digit(at(i_))) throw ExprError{};
                }
                if (at(i_) != U'0') break;
                int_digits += '0';
                ++i_;
            }
            const bool nonzero = is_ascii_digit(at(i_));
            if (nonzero) decimal_tail(int_digits);
            const char32_t c = at(i_);
            if (nonzero && c != U'.' && c != U'e' && c != U'E' && c != U'j' && c != U'J') throw ExprError{};
        } else if (c0 != U'.') {
            decimal_tail(int_digits);
        }
        if (at(i_) == U'.') {
            is_float = true;
            ++i_;
            if (is_ascii_digit(at(i_))) decimal_tail(frac_digits);
        }
        if (at(i_) == U'e' || at(i_) == U'E') {
            is_float = true;
            ++i_;
            bool neg = false;
            if (at(i_) == U'+' || at(i_) == U'-') neg = at(i_++) == U'-';
            if (!is_ascii_digit(at(i_))) throw ExprError{};
            std::string e;
            decimal_tail(e);
            for (const char d : e) exp10 = std::min(exp10 * 10 + (d - '0'), 1000000LL);
            if (neg) exp10 = -exp10;
        }
        if (at(i_) == U'j' || at(i_) == U'J') throw ExprError{};  // imaginary: a complex constant
        end_of_number();
        const double v = decimal_value(int_digits + frac_digits, exp10 - static_cast<long long>(frac_digits.size()));
        if (!is_float && std::isinf(v)) throw ExprError{};
        return v;
    }

    const Token& peek() const { return toks_[pos_]; }
    bool is_op(const char* op) const { return peek().kind == Kind::Op && peek().text == op; }
    void expect(const char* op) {
        if (!is_op(op)) throw ExprError{};
        ++pos_;
    }
    static Item number_item(double v) { return Item{false, v, {}}; }

    static double value_of(const Item& it) {
        if (!it.is_name) return it.value;
        if (it.name == "pi") return kPi;
        if (it.name == "OMEGA_G") return kOmegaG;
        throw ExprError{};
    }

    Item atom() {
        const Token t = peek();
        if (t.kind == Kind::Number) return ++pos_, number_item(t.value);
        if (t.kind == Kind::Name) return ++pos_, Item{true, 0, t.text};
        if (is_op("(")) {
            ++pos_;
            Item it = sum();
            expect(")");
            return it;
        }
        throw ExprError{};
    }

    Item primary() {
        Item it = atom();
        while (is_op("(")) {
            ++pos_;
            double (*f)(double) = nullptr;
            if (it.is_name && it.name == "sqrt") f = [](double x) { return std::sqrt(x); };
            else if (it.is_name && it.name == "sin") f = [](double x) { return std::sin(x); };
            else if (it.is_name && it.name == "cos") f = [](double x) { return std::cos(x); };
            else if (it.is_name && it.name == "acos") f = [](double x) { return std::acos(x); };
            else throw ExprError{};
            const Item arg = sum();
            if (is_op(",")) ++pos_;
            expect(")");
            it = number_item(py_math(f, value_of(arg)));
        }
        return it;
    }

    Item power() {
        Item base = primary();
        if (!is_op("**")) return base;
        ++pos_;
        const Item e = factor();  // right-associative, and "2**-1" is allowed
        return number_item(py_pow(value_of(base), value_of(e)));
    }

    Item factor() {
        if (is_op("+") || is_op("-")) {
            const bool neg = peek().text == "-";
            ++pos_;
            const double v = value_of(factor());
            return number_item(neg ? -v : v);
        }
        return power();
    }

    Item term() {
        Item left = factor();
        while (is_op("*") || is_op("/")) {
            const bool div = peek().text == "/";
            ++pos_;
            const double a = value_of(left), b = value_of(factor());
            if (div && b == 0.0) throw ExprError{};  // ZeroDivisionError
            left = number_item(div ? a / b : a * b);
        }
        return left;
    }

    Item sum() {
        Item left = term();
        while (is_op("+") || is_op("-")) {
            const bool sub = peek().text == "-";
            ++pos_;
            const double a = value_of(left), b = value_of(term());
            left = number_item(sub ? a - b : a + b);
        }
        return left;
    }
};

// ------------------------------------------------------------------------------------------------
// matplotlib.colors.is_color_like for a str

bool colour_name(std::string_view s) { return std::binary_search(kColourNames.begin(), kColourNames.end(), s); }

/// is_color_like(s): 'C<digits>', 'none' in any case, a colour name (as given, or lowercased unless
/// it is one character: 'B' is no colour), hex of 3, 4, 6 or 8 digits, or a grey level float(s)
/// in [0, 1]. str.lower() of a non-ASCII character gives ASCII only for the Kelvin sign.
bool is_color_like(std::string_view s) {
    const std::u32string u = decode(s);
    if (u.size() >= 2 && u[0] == U'C' && std::all_of(u.begin() + 1, u.end(), is_ascii_digit)) return true;
    std::string lower;
    for (const char32_t c : u) {
        if (c == 0x212A) lower += 'k';
        else if (c >= U'A' && c <= U'Z') lower += static_cast<char>(c - U'A' + U'a');
        else append_utf8(lower, c);
    }
    if (lower == "none") return true;
    if (colour_name(s) || (u.size() != 1 && colour_name(lower))) return true;
    if (u.size() > 1 && u[0] == U'#' &&
        std::all_of(u.begin() + 1, u.end(), [](char32_t c) { return c < 0x80 && std::isxdigit(static_cast<int>(c)); }))
        return u.size() == 4 || u.size() == 5 || u.size() == 7 || u.size() == 9;
    const std::optional<double> grey = py_float_of(s);
    return grey && *grey >= 0 && *grey <= 1;
}

// ------------------------------------------------------------------------------------------------
// Value checks of schema.py: _real, _int, _str, _color, _table, _tables, _eps_list, _check_keys

using Keys = std::vector<std::string_view>;

const Keys kKinds{"portrait", "critical_orbits", "hovering_area", "flow_portrait",
                  "flow_hovering_area", "tangent_tori", "sigma_structure"};
const Keys kMapKeys{"Omega0", "theta_w", "tau0", "tau1", "lam"};
const Keys kHovKeys{"kind", "title", "output", "dpi", "figsize", "map", "n_steps", "samples", "seed", "eps", "series"};
const Keys kSeriesKeys{"label", "golden_c", "color", "K_low", "Omega0", "theta_w", "tau0", "tau1", "lam"};
const Keys kFlowHovKeys{"kind",       "title",   "output",  "dpi", "figsize", "system",  "section",
                        "integrator", "outputs", "n_steps", "eps", "samples", "seed",    "models"};
const Keys kSystemKeys{"V1", "V2", "coupling", "eps", "qw1", "qw2", "geometry"};
const Keys kPotentialKeys{"kind", "omega", "alpha"};
const Keys kIntegratorKeys{"stepper", "rtol", "atol", "accuracy"};
const Keys kOutputsKeys{"record", "trajectory_dt"};
const Keys kSteppers{"rk8pd", "rkck", "rkf45", "rk4", "rk2", "msadams", "rk4imp", "rk2imp", "exact"};  // flow.section.STEPPERS

/// An interval of _real (None ends as nullopt).
struct Bounds {
    std::optional<double> lo, hi;
    bool lo_open = false, hi_open = false;
};

std::string join(const Keys& keys) {
    std::string s;
    for (const auto& k : keys) s += (s.empty() ? "" : ", ") + std::string(k);
    return s;
}

bool contains(const Keys& keys, std::string_view k) { return std::find(keys.begin(), keys.end(), k) != keys.end(); }

/// _real: a finite number, or an expression string, inside an interval.
double real(const std::string& where, const toml::node& value, const Bounds& b = {}) {
    double v = 0;
    if (value.is_string()) {
        const std::u32string u = decode(value.as_string()->get());
        if (u.size() > kMaxExpr)
            fail(where + ": expression of " + std::to_string(u.size()) + " characters; allowed: at most " +
                 std::to_string(kMaxExpr));
        try {
            v = Expression(u).evaluate();
        } catch (const ExprError&) {
            fail(where + ": cannot evaluate " + py_repr(value) +
                 "; allowed: a number or an expression of numbers, pi, OMEGA_G, + - * / ** and sqrt, sin, cos, acos");
        }
    } else if (value.is_integer()) {
        v = static_cast<double>(value.as_integer()->get());
    } else if (value.is_floating_point()) {
        v = value.as_floating_point()->get();
    } else {
        fail(where + " must be a number, got " + py_repr(value));
    }
    if (!std::isfinite(v)) fail(where + " must be finite, got " + py_repr(value));
    const bool bad_lo = b.lo && (b.lo_open ? v <= *b.lo : v < *b.lo);
    const bool bad_hi = b.hi && (b.hi_open ? v >= *b.hi : v > *b.hi);
    if (bad_lo || bad_hi) {
        const std::string rng = std::string(b.lo_open || !b.lo ? "(" : "[") + (b.lo ? py_float(*b.lo) : "-inf") + ", " +
                                (b.hi ? py_float(*b.hi) : "inf") + (b.hi_open || !b.hi ? ")" : "]");
        fail(where + " = " + py_repr(value) + " is out of range; allowed: " + rng);
    }
    return v;
}

/// _int: an integer (not a bool or a float) in [lo, hi] (hi: none).
std::int64_t integer(const std::string& where, const toml::node& value, std::int64_t lo,
                     std::optional<std::int64_t> hi = std::nullopt) {
    if (!value.is_integer()) fail(where + " must be an integer, got " + py_repr(value));
    const std::int64_t v = value.as_integer()->get();
    if (v < lo || (hi && v > *hi))
        fail(where + " = " + py_repr(value) + " is out of range; allowed: [" + std::to_string(lo) + ", " +
             (hi ? std::to_string(*hi) : "inf") + "]");
    return v;
}

/// _str: a string with something besides whitespace (str.strip()), optionally one of choices.
std::string text(const std::string& where, const toml::node& value, const Keys* choices = nullptr) {
    bool blank = true;
    if (value.is_string())
        for (const char32_t c : decode(value.as_string()->get())) blank = blank && py_isspace(c);
    if (blank) fail(where + " must be a non-empty string, got " + py_repr(value));
    const std::string& s = value.as_string()->get();
    if (choices && !contains(*choices, s))
        fail(where + " = " + py_repr(value) + " is not allowed; allowed: " + py_choices(*choices));
    return s;
}

std::string text(const std::string& where, const toml::node& value, const Keys& choices) {
    return text(where, value, &choices);
}

/// _color: a string matplotlib takes for a colour.
std::string colour(const std::string& where, const toml::node& value) {
    std::string s = text(where, value);
    if (!is_color_like(s))
        fail(where + " = " + py_repr(value) +
             " is not a matplotlib colour; allowed: a name ('red'), 'C0'..'C9', or hex '#rrggbb'");
    return s;
}

const toml::table& table(const std::string& where, const toml::node& value) {
    if (!value.is_table()) fail(where + " must be a table, got " + py_repr(value));
    return *value.as_table();
}

/// _tables: a non-empty array of at most MAX_PANELS tables ([[what]]; the entries are checked later).
const toml::array& tables(const std::string& where, const toml::node& value, const std::string& what) {
    if (!value.is_array() || value.as_array()->empty())
        fail(where + " must be a non-empty array of tables ([[" + what + "]]), got " + py_repr(value));
    const toml::array& a = *value.as_array();
    if (a.size() > kMaxPanels)
        fail(where + ": " + std::to_string(a.size()) + " " + what + "; allowed: at most " + std::to_string(kMaxPanels) +
             " (one figure)");
    return a;
}

/// _eps_list: distinct numbers, at most MAX_SERIES_POINTS.
std::vector<double> eps_list(const std::string& where, const toml::node& value, const Bounds& b = {}) {
    if (!value.is_array() || value.as_array()->empty())
        fail(where + " must be a non-empty list of numbers, got " + py_repr(value));
    const toml::array& a = *value.as_array();
    if (a.size() > kMaxSeriesPoints)
        fail(where + ": " + std::to_string(a.size()) + " values; allowed: at most " + std::to_string(kMaxSeriesPoints) +
             " (use a sweep for more)");
    std::vector<double> eps;
    for (std::size_t i = 0; i < a.size(); ++i) eps.push_back(real(where + "[" + std::to_string(i) + "]", a[i], b));
    for (std::size_t i = 0; i < eps.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            if (eps[i] == eps[j]) fail(where + " = " + py_repr(value) + " lists a value twice");  // 0.0 == -0.0 in a set too
    return eps;
}

/// _check_keys: unknown keys (in file order), then the required ones in the order given.
void check_keys(const std::string& where, const toml::table& t, const Keys& allowed, const Keys& required = {}) {
    Keys unknown;
    for (const auto& [k, v] : entries(t))
        if (!contains(allowed, k)) unknown.push_back(k);
    if (!unknown.empty())
        fail(where + ": unknown key(s) " + py_choices(unknown) + "; allowed keys: " + join(allowed));
    for (const auto& k : required)
        if (!t.contains(k)) fail(where + ": missing required key " + py_str(k) + "; allowed keys: " + join(allowed));
}

const toml::node* get(const toml::table& t, std::string_view k) { return t.get(k); }

// ------------------------------------------------------------------------------------------------
// Paths: what pathlib makes of a path string

/// str(PurePosixPath(p)): empty and '.' parts dropped, two leading slashes kept (POSIX leaves them
/// to the system), any other run of them one.
std::string posix_path(const std::string& p) {
    std::string root;
    std::size_t start = 0;
    if (!p.empty() && p[0] == '/') {
        start = std::min(p.find_first_not_of('/'), p.size());
        root = start == 2 ? "//" : "/";
    }
    std::string out = root;
    bool first = true;
    for (std::size_t i = start; i <= p.size();) {
        std::size_t j = std::min(p.find('/', i), p.size());
        const std::string part = p.substr(i, j - i);
        if (!part.empty() && part != ".") out += (first ? "" : "/") + part, first = false;
        i = j + 1;
    }
    return out.empty() ? "." : out;
}

/// PurePath.name of a normalised path ("" for "/" or ".").
std::string path_name(const std::string& normalised) {
    const auto slash = normalised.rfind('/');
    std::string name = slash == std::string::npos ? normalised : normalised.substr(slash + 1);
    return name == "." ? "" : name;
}

/// PurePath.stem: the name without its last suffix (a leading or trailing dot is no suffix).
std::string path_stem(const std::string& name) {
    const auto i = name.rfind('.');
    return i != std::string::npos && i > 0 && i + 1 < name.size() ? name.substr(0, i) : name;
}

// ------------------------------------------------------------------------------------------------
// The kinds

/// The five map keys of a table as far as given (optional: absent).
using MapValues = std::array<std::optional<double>, 5>;

/// _map_params: the map keys present, in _MAP_KEYS order (theta_w in (0, pi), lam > 0).
void map_params(const std::string& where, const toml::table& t, MapValues& into) {
    const std::array<Bounds, 5> ranges{Bounds{}, Bounds{0.0, kPi, true, true}, Bounds{}, Bounds{},
                                       Bounds{0.0, std::nullopt, true, false}};
    for (std::size_t k = 0; k < kMapKeys.size(); ++k)
        if (const toml::node* v = get(t, kMapKeys[k])) into[k] = real(where + "." + std::string(kMapKeys[k]), *v, ranges[k]);
}

void parse_hovering_area(const std::string& where, const toml::table& root, SweepScene& s) {
    MapValues scene_map;
    if (const toml::node* m = get(root, "map")) {
        const toml::table& mt = table(where + ".map", *m);
        check_keys(where + ".map", mt, kMapKeys);
        map_params(where + ".map", mt, scene_map);
    }
    s.n_steps = integer(where + ".n_steps", *get(root, "n_steps"), 1, 10'000'000);
    s.eps = eps_list(where + ".eps", *get(root, "eps"));
    const toml::array& sv = tables(where + ".series", *get(root, "series"), "series");
    for (std::size_t i = 0; i < sv.size(); ++i) {
        const std::string sw = where + ".series[" + std::to_string(i) + "]";
        const toml::table& st = table(sw, sv[i]);
        check_keys(sw, st, kSeriesKeys, {"label"});
        MapValues vals{std::nullopt, std::nullopt, 1.0, 0.5, 0.5};  // _MAP_DEFAULTS
        for (std::size_t k = 0; k < vals.size(); ++k)
            if (scene_map[k]) vals[k] = scene_map[k];
        map_params(sw, st, vals);
        Series x;
        if (const toml::node* gc = get(st, "golden_c")) {
            for (const char* k : {"Omega0", "theta_w"})
                if (st.contains(k)) fail(sw + ": give either 'golden_c' or " + py_str(k) + ", not both");
            const double c = real(sw + ".golden_c", *gc);
            if (!(std::fabs(c) < std::fabs(*vals[2])))
                fail(sw + ".golden_c = " + py_repr(*gc) + " is out of range; allowed: |c| < |tau0| = " +
                     py_float(std::fabs(*vals[2])));
            x.golden = true;
            x.golden_c = c;
            vals[0] = vals[1] = std::numeric_limits<double>::quiet_NaN();
        } else {
            for (std::size_t k = 0; k < 2; ++k)
                if (!vals[k])
                    fail(sw + ": missing required key " + py_str(kMapKeys[k]) + " (in [map] or the series), or 'golden_c'");
        }
        x.label = text(sw + ".label", *get(st, "label"));
        if (const toml::node* c = get(st, "color")) x.color = colour(sw + ".color", *c);
        const toml::node* kl = get(st, "K_low");
        if (kl) {
            x.has_K_low = true;
            x.K_low = real(sw + ".K_low", *kl, Bounds{std::nullopt, 0.0, false, true});
        }
        x.map = MapParams{*vals[0], *vals[1], *vals[2], *vals[3], *vals[4]};
        // Python builds the map at every eps (SeriesSpec.map_at(e).build()): its checks, and the band.
        for (const double e : s.eps) {
            double floor = 0;
            try {
                const MapParams m = x.at(e);
                floor = make_truncated_map(e, m.Omega0, m.theta_w, m.tau0, m.tau1, m.lam).band().lo;
            } catch (const std::invalid_argument& err) {
                fail(sw + " at eps = " + py_float(e) + ": " + err.what());
            }
            if (kl && !(x.K_low > floor))
                fail(sw + ".K_low = " + py_repr(*kl) + " lies below the band floor " + py_g6(floor) +
                     " of the map at eps = " + py_float(e) + "; allowed: (" + py_g6(floor) + ", 0)");
        }
        s.series.push_back(std::move(x));
    }
    const toml::node* samples = get(root, "samples");
    s.samples = samples ? integer(where + ".samples", *samples, 1, 100'000'000) : 100'000;
    const toml::node* seed = get(root, "seed");
    s.seed = seed ? static_cast<std::uint64_t>(integer(where + ".seed", *seed, 0, INT64_MAX)) : 0;
}

PotentialSpec potential(const std::string& where, const toml::node& value) {
    const toml::table& t = table(where, value);
    check_keys(where, t, kPotentialKeys, {"kind", "omega"});
    PotentialSpec p;
    p.kind = text(where + ".kind", *get(t, "kind"), Keys{"harmonic", "tan"});
    const Bounds scale{1e-100, 1e100};
    p.omega = real(where + ".omega", *get(t, "omega"), scale);
    if (p.kind == "tan") {
        if (!t.contains("alpha")) fail(where + ": missing required key 'alpha' for kind = 'tan'");
        p.alpha = real(where + ".alpha", *get(t, "alpha"), scale);
    } else if (t.contains("alpha")) {
        fail(where + ": 'alpha' is only used with kind = 'tan', got kind = 'harmonic'");
    }
    return p;
}

std::vector<std::array<double, 3>> coupling(const std::string& where, const toml::node& value) {
    if (value.is_string() && value.as_string()->get() == "bilinear") return {{1.0, 1.0, 1.0}};
    if (value.is_string() && value.as_string()->get() == "none") return {};
    if (!value.is_array() || value.as_array()->empty() || value.as_array()->size() > 64)
        fail(where + " must be 'bilinear', 'none' or a list of 1..64 terms [c, i, j] (c q1^i q2^j), got " + py_repr(value));
    std::vector<std::array<double, 3>> terms;
    const toml::array& a = *value.as_array();
    for (std::size_t k = 0; k < a.size(); ++k) {
        const std::string tw = where + "[" + std::to_string(k) + "]";
        if (!a[k].is_array() || a[k].as_array()->size() != 3)
            fail(tw + " must be a term [c, i, j] (c q1^i q2^j), got " + py_repr(a[k]));
        const toml::array& term = *a[k].as_array();
        const double c = real(tw + "[0]", term[0]);
        const auto i = integer(tw + "[1]", term[1], 0, 20);
        const auto j = integer(tw + "[2]", term[2], 0, 20);
        terms.push_back({c, static_cast<double>(i), static_cast<double>(j)});
    }
    return terms;
}

std::shared_ptr<const Potential> build(const PotentialSpec& p) {
    if (p.kind == "tan") return std::make_shared<Tan>(p.omega, p.alpha);
    return std::make_shared<Harmonic>(p.omega);
}

/// _system: the [system] table, then what StepSystem checks when SystemSpec.build() makes it.
SystemSpec system(const std::string& where, const toml::node& value) {
    const toml::table& t = table(where, value);
    check_keys(where, t, kSystemKeys, {"V1", "V2"});
    SystemSpec s;
    s.V1 = potential(where + ".V1", *get(t, "V1"));
    s.V2 = potential(where + ".V2", *get(t, "V2"));
    if (const toml::node* c = get(t, "coupling")) s.coupling = coupling(where + ".coupling", *c);
    if (const toml::node* e = get(t, "eps")) s.eps = real(where + ".eps", *e, Bounds{-10.0, 10.0});
    const Bounds negative{std::nullopt, 0.0, false, true};
    if (const toml::node* q = get(t, "qw1")) s.qw1 = real(where + ".qw1", *q, negative);
    if (const toml::node* q = get(t, "qw2")) s.qw2 = real(where + ".qw2", *q, negative);
    if (const toml::node* g = get(t, "geometry")) s.geometry = text(where + ".geometry", *g, Keys{"none", "wall", "step"});
    const auto bad = [&](const std::string& msg) { fail(where + ": " + msg); };
    if (s.eps != 0 && s.coupling.empty()) bad("eps != 0 needs a coupling (e.g. hovering.Bilinear())");
    FlowSystem fs;
    fs.V1 = build(s.V1);
    fs.V2 = build(s.V2);
    for (const auto& [name, q, pot] : {std::tuple{"qw1", s.qw1, fs.V1}, std::tuple{"qw2", s.qw2, fs.V2}})
        if (!(std::fabs(q) < pot->q_limit()))
            bad(std::string(name) + " = " + py_float(q) + " lies outside the well of " + pot->name() + " (|" + name +
                "| < " + py_float(pot->q_limit()) + ")");
    fs.coupling.terms = s.coupling;
    fs.eps = s.eps;
    fs.qw1 = s.qw1;
    fs.qw2 = s.qw2;
    fs.geometry = s.geometry == "none" ? Geometry::None : s.geometry == "wall" ? Geometry::Wall : Geometry::Step;
    try {
        fs.validate();
    } catch (const std::invalid_argument& e) {
        bad(e.what());
    }
    return s;
}

void parse_flow_hovering_area(const std::string& where, const toml::table& root, SweepScene& s) {
    s.system = system(where + ".system", *get(root, "system"));
    s.h = 1.0;
    if (const toml::node* sec = get(root, "section")) {
        const toml::table& st = table(where + ".section", *sec);
        check_keys(where + ".section", st, {"h"}, {"h"});
        s.h = real(where + ".section.h", *get(st, "h"), Bounds{0.0, std::nullopt, true, false});
    }
    const double hw = build(s.system.V1)->V(s.system.qw1) + build(s.system.V2)->V(s.system.qw2);
    if (!(s.h > hw))
        fail(where + ".section.h = " + py_float(s.h) +
             " is out of range; allowed: above the step energy V1(qw1) + V2(qw2) + eps Vc(qw1, qw2) = " + py_g6(hw) +
             " (no tangency band below it)");
    if (const toml::node* in = get(root, "integrator")) {
        const std::string iw = where + ".integrator";
        const toml::table& it = table(iw, *in);
        check_keys(iw, it, kIntegratorKeys);
        const Bounds tol{1e-15, 1e-2};
        IntegratorSpec& g = s.integrator;
        g.rtol = it.contains("rtol") ? real(iw + ".rtol", *get(it, "rtol"), tol) : 1e-10;
        g.atol = it.contains("atol") ? real(iw + ".atol", *get(it, "atol"), tol) : g.rtol;
        g.stepper = it.contains("stepper") ? text(iw + ".stepper", *get(it, "stepper"), kSteppers) : "rk8pd";
        if (const toml::node* acc = get(it, "accuracy")) {
            Keys both;
            for (const char* k : {"atol", "rtol", "stepper"})  // sorted, as Python lists them
                if (it.contains(k)) both.push_back(k);
            if (!both.empty())
                fail(iw + ": 'accuracy' picks the stepper and tolerances itself; remove " + py_list(both) + " or 'accuracy'");
            g.accuracy = real(iw + ".accuracy", *acc, Bounds{1e-13, 1e-2});
        }
    }
    if (const toml::node* out = get(root, "outputs")) {
        const std::string ow = where + ".outputs";
        const toml::table& ot = table(ow, *out);
        check_keys(ow, ot, kOutputsKeys);
        if (const toml::node* rv = get(ot, "record")) {
            if (!rv->is_array()) fail(ow + ".record must be a list of names from ['regions'], got " + py_repr(*rv));
            for (const auto& r : *rv->as_array()) text(ow + ".record", r, Keys{"regions"});
            if (rv->as_array()->empty())  // every entry is 'regions' by now: only an empty list lacks it
                fail(ow + ".record = " + py_repr(*rv) + " lacks ['regions']: a flow_hovering_area figure is drawn from them");
        }
        if (ot.contains("trajectory_dt")) fail(ow + ".trajectory_dt is only used by scenes that record 'trajectory'");
    }
    if (s.system.geometry != "step")
        fail(where + ".system.geometry = " + py_str(s.system.geometry) +
             ": a flow_hovering_area scene draws the regions of the step; allowed: 'step'");
    s.eps = eps_list(where + ".eps", *get(root, "eps"), Bounds{-1.0, 1.0});
    if (const toml::node* mv = get(root, "models")) {
        if (!mv->is_array()) fail(where + ".models must be a list from ['onset', 'measured'], got " + py_repr(*mv));
        s.models.clear();
        for (const auto& m : *mv->as_array()) s.models.push_back(text(where + ".models", m, Keys{"onset", "measured"}));
    }
    s.n_steps = integer(where + ".n_steps", *get(root, "n_steps"), 1, 1'000'000);
    const toml::node* samples = get(root, "samples");
    s.samples = samples ? integer(where + ".samples", *samples, 16, 10'000'000) : 1000;
    const toml::node* seed = get(root, "seed");
    s.seed = seed ? static_cast<std::uint64_t>(integer(where + ".seed", *seed, 0, INT64_MAX)) : 0;
}

/// Replace the float literal that ends at `at` (toml++'s position just after it, in bytes or in
/// code points; toml++ quotes it without underscores) by inf; false if it is not found there.
bool literal_to_inf(std::string& doc, std::string_view literal, const toml::source_position& at) {
    std::size_t start = 0;
    for (std::size_t line = 1; line < at.line; ++line) {
        start = doc.find('\n', start);
        if (start == std::string::npos) return false;
        ++start;
    }
    const std::string_view line = std::string_view(doc).substr(start, doc.find('\n', start) - start);
    std::size_t by_code_point = 0;  // the byte after column - 1 code points
    for (std::size_t k = 1; k < at.column && by_code_point < line.size(); ++k) {
        ++by_code_point;
        while (by_code_point < line.size() && (static_cast<unsigned char>(line[by_code_point]) & 0xC0) == 0x80)
            ++by_code_point;
    }
    for (const std::size_t end : {static_cast<std::size_t>(at.column) - 1, by_code_point}) {
        if (end > line.size()) continue;
        // toml++ quotes the literal without its underscores.
        std::size_t i = end, j = literal.size();
        while (i > 0 && j > 0) {
            if (line[i - 1] == '_') --i;
            else if (line[i - 1] == literal[j - 1]) --i, --j;
            else break;
        }
        if (j == 0) {
            doc.replace(start + i, end - i, "inf");
            return true;
        }
    }
    return false;
}

/// The TOML document, or tomllib's "not valid TOML" (with toml++'s own detail). tomllib reads a float
/// literal beyond the double range as inf where toml++ refuses it (the one float error left once
/// toml++ has checked the literal's syntax): such literals become inf, sign kept, and the text is
/// read again.
toml::table parse_toml(std::string doc, const std::string& where) {
    // tomllib reads a byte-order mark as text (an invalid statement); toml++ would skip it.
    if (doc.compare(0, 3, "\xEF\xBB\xBF") == 0) fail(where + ": not valid TOML: Invalid statement (at line 1, column 1)");
    for (;;) {
        try {
            return toml::parse(doc);
        } catch (const toml::parse_error& e) {
            const std::string_view d = e.description();
            constexpr std::string_view head = "Error while parsing floating-point: '", tail = "' could not be interpreted as a value";
            if (d.size() > head.size() + tail.size() && d.substr(0, head.size()) == head &&
                d.substr(d.size() - tail.size()) == tail &&
                literal_to_inf(doc, d.substr(head.size(), d.size() - head.size() - tail.size()), e.source().begin))
                continue;
            fail(where + ": not valid TOML: " + std::string(d) + " (at line " + std::to_string(e.source().begin.line) +
                 ", column " + std::to_string(e.source().begin.column) + ")");
        }
    }
}

/// parse_scene for the sweep kinds: `origin` is the path as given (its name is `where` in the
/// messages, its stem the scene's name), `path` what SweepScene.path holds.
SweepScene parse(const std::string& doc, const std::string& origin, const std::string& path) {
    const std::string normalised = posix_path(origin);
    const std::string where = path_name(normalised);
    SweepScene s;
    s.path = path;
    s.name = path_stem(where);
    const toml::table root = parse_toml(doc, where);
    if (!root.contains("kind")) fail(where + ": missing required key 'kind'; allowed: " + py_choices(kKinds));
    s.kind = text(where + ".kind", *get(root, "kind"), kKinds);
    const bool truncated = s.kind == "hovering_area";
    if (!truncated && s.kind != "flow_hovering_area")
        fail(where + ".kind = " + py_str(s.kind) +
             ": hovering_sweep runs the sweep kinds 'hovering_area' and 'flow_hovering_area'; draw this scene with: "
             "python -m hovering scene " + normalised);
    if (truncated) check_keys(where, root, kHovKeys, {"kind", "output", "n_steps", "eps", "series"});
    else check_keys(where, root, kFlowHovKeys, {"kind", "output", "system", "n_steps", "eps"});
    s.title = root.contains("title") ? text(where + ".title", *get(root, "title")) : s.name;
    s.output = posix_path(text(where + ".output", *get(root, "output")));
    if (const toml::node* d = get(root, "dpi")) s.dpi = static_cast<int>(integer(where + ".dpi", *d, 30, 1200));
    if (const toml::node* f = get(root, "figsize")) {
        if (!f->is_array() || f->as_array()->size() != 2)
            fail(where + ".figsize must be [width, height] in inches, got " + py_repr(*f));
        for (std::size_t i = 0; i < 2; ++i)
            real(where + ".figsize[" + std::to_string(i) + "]", (*f->as_array())[i], Bounds{0.5, 60.0});
    }
    if (truncated) parse_hovering_area(where, root, s);
    else parse_flow_hovering_area(where, root, s);
    return s;
}

}  // namespace

std::pair<double, double> golden_family(double eps, double c, double tau0) {
    for (const auto& [name, v] : {std::pair{"eps", eps}, std::pair{"c", c}, std::pair{"tau0", tau0}})
        if (!std::isfinite(v)) fail(std::string(name) + " must be finite, got " + py_float(v));
    if (!(std::fabs(c) < std::fabs(tau0)))
        fail("c must satisfy |c| < |tau0| = " + py_float(std::fabs(tau0)) + ", got c = " + py_float(c));
    const double Omega0 = kOmegaG - 0.5 * c * eps;
    if (!(std::fabs(Omega0) <= 1e6))
        fail("eps = " + py_float(eps) + " and c = " + py_float(c) + " give Omega0 = Omega_G - c eps / 2 = " +
             py_g6(Omega0) + "; allowed: |Omega0| <= 1e6 (a larger rotation cannot be reduced mod 2 pi accurately)");
    // Python takes NumPy's arccos, which on AVX-512 machines can differ from the C library's by an ulp.
    return {Omega0, std::acos((c / tau0) * std::sin(0.5 * kOmegaG - 0.25 * c * eps))};
}

MapParams Series::at(double eps) const {
    MapParams m = map;
    if (golden) std::tie(m.Omega0, m.theta_w) = golden_family(eps, golden_c, m.tau0);
    return m;
}

SweepScene parse_sweep_scene(const std::string& text, const std::string& where) { return parse(text, where, ""); }

SweepScene load_sweep_scene(const std::string& path) {
    // load_scene's checks, on the path as pathlib has it.
    const std::string p = posix_path(path);
    const std::string name = path_name(p);
    struct stat st{};
    if (::stat(p.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) fail(p + ": not a regular file (a scene is a .toml file)");
    std::ifstream f(p, std::ios::binary);
    if (!f) {
        const int err = errno;  // what open() reported, as Python's OSError text
        throw std::runtime_error("[Errno " + std::to_string(err) + "] " + std::strerror(err) + ": " + py_str(p));
    }
    std::string raw(kMaxSceneBytes + 1, '\0');
    f.read(raw.data(), static_cast<std::streamsize>(raw.size()));
    raw.resize(static_cast<std::size_t>(f.gcount()));
    if (raw.size() > kMaxSceneBytes)
        fail(name + ": larger than " + std::to_string(kMaxSceneBytes) + " bytes; a scene file is a few hundred");
    if (const std::size_t bad = utf8_error(raw); bad != std::string::npos)
        fail(name + ": not UTF-8 text (TOML files are UTF-8): byte " + std::to_string(bad));
    return parse(raw, p, p);
}

}  // namespace hovering::scene
